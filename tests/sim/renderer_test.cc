// The renderer against the analytic scene: depth and labels against ray casting, projections of
// a marker against the pinhole model, stereo geometry, texture filtering and determinism.

#include "sbaslam/sim/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sbaslam/sim/procedural_textures.h"
#include "sbaslam/sim/random.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam::sim {
namespace {

ImageEffects no_effects() {
  ImageEffects e;
  e.sensor_noise = e.motion_blur = e.exposure_changes = e.vignetting = false;
  return e;
}

// The straight street at a third of KITTI's resolution, built once for the whole file.
const Scene& small_street() {
  static const Scene scene = [] {
    SceneOptions o;
    o.name = "straight";
    o.seed = 7;
    o.resolution_scale = 0.3;
    o.effects = no_effects();
    return make_scene(o);
  }();
  return scene;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

TEST(SimRenderer, DepthAndLabelsAgreeWithRayCasting) {
  const Scene& scene = small_street();
  const ViewCamera& cam = scene.camera;
  for (int frame : {0, 40}) {
    const double t = scene.time_of(frame);
    const SE3 T_wc = scene.left_camera_pose(t);
    ViewLayers layers;
    render_view(scene.world, cam, T_wc, t, layers);
    int checked = 0, label_agree = 0;
    std::vector<double> depth_error;
    for (int y = 1; y < cam.height - 1; y += 3) {
      for (int x = 1; x < cam.width - 1; x += 3) {
        const Vec3 ray_c((x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1.0);
        const auto hit = raycast(scene.world, T_wc.translation(), T_wc.so3() * ray_c, t);
        ++checked;
        const std::uint8_t expected = hit ? hit->label : label::kSky;
        if (layers.label.at<std::uint8_t>(y, x) == expected) ++label_agree;
        if (!hit) {
          EXPECT_EQ(layers.depth.at<float>(y, x), 0.0f) << x << "," << y;
          continue;
        }
        const double z = (T_wc.inverse() * hit->point).z();
        depth_error.push_back(std::abs(layers.depth.at<float>(y, x) - z) / z);
      }
    }
    // Pixels whose centre falls within rounding of an edge may differ; nearly all must agree.
    EXPECT_GT(label_agree, 0.99 * checked) << "frame " << frame;
    ASSERT_GT(depth_error.size(), 100u);
    EXPECT_LT(percentile(depth_error, 0.5), 1e-5);
    EXPECT_LT(percentile(depth_error, 0.98), 1e-4);
  }
}

// A wall with a white disc marker: the disc's centroid in the image must be the projection of
// its centre under the ground-truth pose.
TEST(SimRenderer, MarkerCentreProjectsWhereTheModelSays) {
  World world;
  world.lighting.sky = false;
  const int gray = world.add_texture(cv::Mat(64, 64, CV_8U, cv::Scalar(0)), TextureWrap::kRepeat);
  const int marker = world.add_texture(marker_texture(), TextureWrap::kClamp);
  FaceSkin tiled;
  tiled.texels_per_metre = 20.0;
  FaceSkin fit;
  fit.fit = true;
  // Wall in the plane y = 5 facing -y; the marker 1 cm in front of it.
  world.quads.push_back(make_quad(Vec3(-5, 5, 4), Vec3(10, 0, 0), Vec3(0, 0, -4), gray,
                                  label::kBuilding, tiled, world));
  const Vec3 centre(0.3, 4.99, 1.7);
  // The disc's radius is a quarter of the quad's size. Small, because the centroid of a slanted
  // disc's image moves away from its centre's projection with the square of its radius.
  const double size = 0.12;
  world.quads.push_back(make_quad(centre + Vec3(-0.5 * size, 0, 0.5 * size), Vec3(size, 0, 0),
                                  Vec3(0, 0, -size), marker, label::kTrafficSign, fit, world));
  const ViewCamera cam{458.654, 457.296, 367.215, 248.375, 752, 480};
  Random rng(3);
  for (int trial = 0; trial < 6; ++trial) {
    // Looking roughly at the marker from 2-4 m, from varying angles, with roll.
    const Vec3 eye(rng.uniform(-1.5, 1.5), rng.uniform(1.0, 3.0), rng.uniform(0.8, 2.5));
    const Vec3 look =
        (centre + Vec3(rng.uniform(-0.5, 0.5), 0, rng.uniform(-0.3, 0.3)) - eye).normalized();
    const Vec3 right = look.cross(Vec3::UnitZ()).normalized();
    Mat3 R;
    R << right, look.cross(right), look;
    const SE3 T_wc = SE3(SO3::from_matrix(R), eye) *
                     SE3(SO3::exp(Vec3(0, 0, rng.uniform(-0.4, 0.4))), Vec3::Zero());
    ViewLayers layers;
    render_view(world, cam, T_wc, 0.0, layers);
    double sum = 0.0, sx = 0.0, sy = 0.0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const double w = layers.label.at<std::uint8_t>(y, x) == label::kTrafficSign
                             ? layers.radiance.at<float>(y, x)
                             : 0.0;
        sum += w;
        sx += w * x;
        sy += w * y;
      }
    ASSERT_GT(sum, 5.0) << "marker not visible in trial " << trial;
    const Vec3 p = T_wc.inverse() * centre;
    const Vec2 expected(cam.fx * p.x() / p.z() + cam.cx, cam.fy * p.y() / p.z() + cam.cy);
    EXPECT_LT((Vec2(sx / sum, sy / sum) - expected).norm(), 0.5) << "trial " << trial;
    EXPECT_LT((Vec2(sx / sum, sy / sum) - expected).norm(), 0.1) << "trial " << trial;
  }
}

float bilinear_at(const cv::Mat& img, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  auto at = [&](int yy, int xx) { return static_cast<float>(img.at<std::uint8_t>(yy, xx)); };
  const float top = at(y0, x0) + ax * (at(y0, x0 + 1) - at(y0, x0));
  const float bottom = at(y0 + 1, x0) + ax * (at(y0 + 1, x0 + 1) - at(y0 + 1, x0));
  return top + ay * (bottom - top);
}

TEST(SimRenderer, RightImageFollowsStereoGeometry) {
  const Scene& scene = small_street();
  const ViewCamera& cam = scene.camera;
  const int frame = 20;
  const StereoFrame f = render_frame(scene, frame);
  ViewLayers right;
  render_view(scene.world, cam, scene.right_camera_pose(f.time), f.time, right);
  std::vector<double> diffs;
  for (int y = 2; y < cam.height - 2; y += 2) {
    for (int x = 2; x < cam.width - 2; x += 2) {
      const float z = f.depth.at<float>(y, x);
      if (z <= 0.0f) continue;
      const double xr = x - cam.fx * scene.baseline / z;
      if (xr < 1.0 || xr > cam.width - 2.0) continue;
      // Same surface in the right view (not occluded there): its depth must agree.
      const int xi = static_cast<int>(std::lround(xr));
      if (std::abs(right.depth.at<float>(y, xi) - z) > 0.01f * z) continue;
      diffs.push_back(std::abs(bilinear_at(f.right, xr, y) - f.left.at<std::uint8_t>(y, x)));
    }
  }
  ASSERT_GT(diffs.size(), 2000u);
  // Texture resampling differs slightly between the views (another footprint, another mip level).
  EXPECT_LT(percentile(diffs, 0.5), 2.0);
  EXPECT_LT(percentile(diffs, 0.9), 8.0);
  // A wrong disparity sign or scale would break it: shift by 3 px and the match is lost.
  std::vector<double> shifted;
  for (int y = 2; y < cam.height - 2; y += 2)
    for (int x = 2; x < cam.width - 2; x += 2) {
      const float z = f.depth.at<float>(y, x);
      if (z <= 0.0f) continue;
      const double xr = x - cam.fx * scene.baseline / z + 3.0;
      if (xr < 1.0 || xr > cam.width - 2.0) continue;
      shifted.push_back(std::abs(bilinear_at(f.right, xr, y) - f.left.at<std::uint8_t>(y, x)));
    }
  EXPECT_GT(percentile(shifted, 0.5), 2.0 * percentile(diffs, 0.5) + 1.0);
}

// A fine checkerboard far away and at a grazing angle must average out to gray instead of
// aliasing into a random pattern of bright and dark pixels.
TEST(SimRenderer, MipMappingAveragesDistantTexture) {
  cv::Mat checker(256, 256, CV_8U);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) checker.at<std::uint8_t>(y, x) = ((x + y) % 2) ? 255 : 0;
  World world;
  const int tex = world.add_texture(checker, TextureWrap::kRepeat);
  FaceSkin skin;
  skin.texels_per_metre = 100.0;  // 1 cm checks
  world.quads.push_back(make_quad(Vec3(-50, 200, 0), Vec3(100, 0, 0), Vec3(0, -200, 0), tex,
                                  label::kRoad, skin, world));
  const ViewCamera cam{300, 300, 160, 120, 320, 240};
  Mat3 R;
  R << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // looking along +y, x right, image y down = world -z
  ViewLayers layers;
  render_view(world, cam, SE3(SO3::from_matrix(R), Vec3(0, 0, 1.5)), 0.0, layers);
  // Rows below the horizon at 15 to 100 m: footprints of 5 to 30 checks per pixel.
  cv::Mat band = layers.radiance.rowRange(125, 150);
  cv::Scalar mean, stddev;
  cv::meanStdDev(band, mean, stddev);
  const float expected = world.shade(world.quads[0], Vec3::UnitZ()) * 127.5f / 255.0f;
  EXPECT_NEAR(mean[0], expected, 0.03);
  EXPECT_LT(stddev[0], 0.03) << "distant checks alias";
}

TEST(SimRenderer, SameSeedSameBytesOtherSeedOtherBytes) {
  SceneOptions o;
  o.name = "room";
  o.seed = 5;
  o.resolution_scale = 0.25;
  const Scene a = make_scene(o);
  const Scene b = make_scene(o);
  o.seed = 6;
  const Scene c = make_scene(o);
  for (int frame : {3, 330}) {  // the second frame is in the dark segment
    const StereoFrame fa = render_frame(a, frame), fb = render_frame(b, frame),
                      fc = render_frame(c, frame);
    EXPECT_EQ(cv::norm(fa.left, fb.left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.right, fb.right, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.depth, fb.depth, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.label, fb.label, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(fa.left, fc.left, cv::NORM_L1), 0.0);
  }
  // Rendering order must not matter: frame 3 after frame 330 is the same.
  EXPECT_EQ(cv::norm(render_frame(a, 3).left, render_frame(b, 3).left, cv::NORM_INF), 0.0);
}

TEST(SimRenderer, TexturesGiveCornersButNotNoise) {
  const Scene& scene = small_street();
  const StereoFrame f = render_frame(scene, 10);
  // FAST-like check without OpenCV's detector: count pixels with strong local contrast; a
  // street has many, but far from all pixels (pure noise would light up nearly all).
  cv::Mat grad_x, grad_y, magnitude;
  cv::Sobel(f.left, grad_x, CV_32F, 1, 0);
  cv::Sobel(f.left, grad_y, CV_32F, 0, 1);
  cv::magnitude(grad_x, grad_y, magnitude);
  const double strong =
      cv::countNonZero(magnitude > 150.0) / static_cast<double>(magnitude.total());
  EXPECT_GT(strong, 0.03);
  EXPECT_LT(strong, 0.6);
}

}  // namespace
}  // namespace sbaslam::sim
