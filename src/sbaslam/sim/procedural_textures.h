#pragma once
// Procedural grayscale textures for the synthetic world. Each generator is a pure function of its
// seed. They aim at what matters for feature tracking on real images: structure at several scales
// (noise octaves, bricks, tiles, windows, glyphs), sharp man-made edges and corners where real
// scenes have them, and smooth regions where real scenes are smooth. All sizes are powers of two;
// the comment of each generator gives the metric size a texel is meant to cover.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace sbaslam::sim {

// Repeating fractal value noise in [-1, 1]; base_cell is the period of the coarsest octave in
// texels (a power of two dividing the size).
cv::Mat fractal_noise(int width, int height, int base_cell, int octaves, double persistence,
                      std::uint64_t seed);

enum class FacadeStyle { kBrick, kPlaster, kConcretePanels, kGlassOffice };
constexpr int kFacadeStyleCount = 4;

// 1024x1024 texels at 2 cm (20.48 m repeat), six floors of 3.41 m and six window columns.
cv::Mat facade_texture(FacadeStyle style, std::uint64_t seed);
// 1024x512 texels at 2.5 cm: a 25.6 m long piece of a four-lane road (12.8 m across, rows grow
// to the right of the driving direction): asphalt, centre double line, dashed lane lines, edge
// lines; with_arrows adds direction arrows.
cv::Mat road_texture(bool with_arrows, std::uint64_t seed);
// 1024x1024 texels covering a 24 m intersection square with zebra crossings on its four sides.
cv::Mat intersection_texture(std::uint64_t seed);
// 512x128 texels at 2.5 cm along, stretched to the parking lane's width across: bay lines.
cv::Mat parking_texture(std::uint64_t seed);
// 512x512 texels at 2 cm: paving slabs of 32 cm.
cv::Mat sidewalk_texture(std::uint64_t seed);
// 512x512 texels at 3 cm: grass and soil.
cv::Mat terrain_texture(std::uint64_t seed);
// 256x256 texels at 2.5 cm, rows across the track: sleepers and two rails in rows 20..108.
cv::Mat rail_texture(std::uint64_t seed);
// 512x512 texels at 2 cm: leaves of tree crowns and hedges.
cv::Mat foliage_texture(std::uint64_t seed);
// 256x256 texels at 1 cm: bark or painted metal with vertical streaks.
cv::Mat streaked_texture(int base_value, std::uint64_t seed);
// 512x256 texels at 1 cm: wooden planks of a fence.
cv::Mat fence_texture(std::uint64_t seed);
// 512x256 clamp: a car's side (windows, doors, wheels); 256x256 clamp: its front or rear.
cv::Mat car_side_texture(std::uint64_t seed);
cv::Mat car_end_texture(bool front, std::uint64_t seed);
// 128x256 clamp: a pedestrian seen from any side (head, torso, legs).
cv::Mat person_texture(std::uint64_t seed);
// 256x256 clamp: a traffic sign face (kind 0..3: prohibition, warning, information, direction).
cv::Mat sign_texture(int kind, std::uint64_t seed);
// 128x256 clamp: a traffic light head with one lamp lit.
cv::Mat traffic_light_texture(std::uint64_t seed);
// 512x128 clamp: a shop sign with a random text, unique per seed.
cv::Mat shop_sign_texture(std::uint64_t seed);
// Indoor: 512x512 poster; 1024x1024 floor mats at 1 cm; 512x512 ceiling tiles at 2 cm;
// 512x512 cardboard or crate at 0.5 cm; 512x512 rough plaster wall at 1 cm.
cv::Mat poster_texture(std::uint64_t seed);
cv::Mat floor_mat_texture(std::uint64_t seed);
cv::Mat ceiling_texture(std::uint64_t seed);
cv::Mat box_texture(bool crate, std::uint64_t seed);
cv::Mat wall_texture(std::uint64_t seed);
// 256x256 clamp: a white disc of radius 64 texels centred on a black square. Its centroid is the
// texture's centre, which tests use to check projections.
cv::Mat marker_texture();

// Reads a photograph as a texture: grayscale, resized to the nearest power-of-two size (at most
// 1024). Throws sbaslam::Error naming the file when it cannot be read.
cv::Mat photo_texture(const std::string& path);

}  // namespace sbaslam::sim
