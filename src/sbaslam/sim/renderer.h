#pragma once
// Rasteriser of the quad world into one pinhole view. Each quad is clipped against the near plane,
// projected, and filled scanline by scanline in two passes. The visibility pass evaluates the
// plane's inverse depth (linear in the pixel coordinates) into a z-buffer and records which quad
// wins each pixel; quads go nearest first. The shading pass then textures every covered pixel
// exactly once, by runs of pixels on the same quad, reading the texture by inverse mapping
// through the plane with a mip level from the pixel's footprint. Pixel (x, y) samples the ray
// through the integer coordinates (x, y): a point X in the camera frame lands at
// (fx X/Z + cx, fy Y/Z + cy), as for every consumer of the images.

#include <opencv2/core.hpp>

#include "sbaslam/core/lie.h"
#include "sbaslam/sim/world.h"

namespace sbaslam::sim {

struct ViewCamera {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;

  // The same camera for an image scaled by `factor` (for quick, small renders).
  ViewCamera scaled(double factor) const;
};

struct ViewLayers {
  cv::Mat radiance;  // CV_32F, linear scene radiance, about [0, 1.3]
  cv::Mat depth;     // CV_32F, metric z in the camera frame; 0 where nothing was hit (sky)
  cv::Mat label;     // CV_8U, Cityscapes label id
};

constexpr double kNearPlane = 0.05;  // metres

// Renders the world at time t (moving objects posed at t) into `layers`, reusing its buffers.
void render_view(const World& world, const ViewCamera& camera, const SE3& T_world_camera,
                 double time, ViewLayers& layers);

}  // namespace sbaslam::sim
