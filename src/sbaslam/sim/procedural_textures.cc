#include "sbaslam/sim/procedural_textures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "sbaslam/core/error.h"
#include "sbaslam/sim/random.h"

namespace sbaslam::sim {
namespace {

// One octave of repeating value noise: a random lattice with the given period, cubic-upsampled.
cv::Mat noise_octave(int width, int height, int cell, Random& rng) {
  const int gw = std::max(1, width / cell);
  const int gh = std::max(1, height / cell);
  cv::Mat grid(gh, gw, CV_32F);
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < gw; ++x) grid.at<float>(y, x) = static_cast<float>(rng.uniform(-1.0, 1.0));
  if (cell == 1) return grid;
  // Padding by wrapping keeps the upsampled result periodic.
  const int pad = 2;
  cv::Mat padded;
  cv::copyMakeBorder(grid, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::Mat up;
  cv::resize(padded, up, cv::Size(padded.cols * cell, padded.rows * cell), 0, 0, cv::INTER_CUBIC);
  return up(cv::Rect(pad * cell, pad * cell, width, height)).clone();
}

cv::Mat to_u8(const cv::Mat& values) {
  cv::Mat out;
  values.convertTo(out, CV_8U);  // saturates
  return out;
}

// mean + contrast * noise, as float.
cv::Mat shaded_noise(int w, int h, int cell, int octaves, double persistence, double mean,
                     double contrast, std::uint64_t seed) {
  cv::Mat n = fractal_noise(w, h, cell, octaves, persistence, seed);
  return n * contrast + mean;
}

void fill_rect(cv::Mat& img, int x, int y, int w, int h, float value) {
  const cv::Rect r = cv::Rect(x, y, w, h) & cv::Rect(0, 0, img.cols, img.rows);
  if (r.area() > 0) img(r).setTo(value);
}

void add_rect(cv::Mat& img, int x, int y, int w, int h, float delta) {
  const cv::Rect r = cv::Rect(x, y, w, h) & cv::Rect(0, 0, img.cols, img.rows);
  if (r.area() > 0) img(r) += delta;
}

// A random word of capital letters and digits, for text-like glyphs.
std::string random_text(Random& rng, int min_len, int max_len) {
  static const char kChars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  const int len = rng.integer(min_len, max_len);
  std::string s;
  for (int i = 0; i < len; ++i) s += kChars[rng.integer(0, 35)];
  return s;
}

// Draws text centred in a rectangle, scaled to fit it.
void draw_text(cv::Mat& img, const std::string& text, const cv::Rect& box, double value, int font,
               int thickness) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font, 1.0, thickness, &baseline);
  const double scale = std::min(0.9 * box.width / std::max(1, size.width),
                                0.7 * box.height / std::max(1, size.height));
  const cv::Size s2 = cv::getTextSize(text, font, scale, thickness, &baseline);
  const cv::Point origin(box.x + (box.width - s2.width) / 2, box.y + (box.height + s2.height) / 2);
  cv::putText(img, text, origin, font, scale, cv::Scalar(value), thickness, cv::LINE_AA);
}

// One window of a facade: frame, glass with smooth reflections, sometimes a blind or a mullion.
void draw_window(cv::Mat& img, const cv::Rect& r, float frame, Random& rng) {
  fill_rect(img, r.x - 4, r.y - 4, r.width + 8, r.height + 8, frame);
  const float glass = static_cast<float>(rng.uniform(25.0, 80.0));
  cv::Mat pane = img(r & cv::Rect(0, 0, img.cols, img.rows));
  for (int y = 0; y < pane.rows; ++y)
    for (int x = 0; x < pane.cols; ++x)
      pane.at<float>(y, x) = glass + 30.0f * static_cast<float>(x + y) / (pane.cols + pane.rows);
  if (rng.chance(0.35)) {  // a blind pulled down part of the way
    const int drop = static_cast<int>(r.height * rng.uniform(0.2, 0.8));
    fill_rect(img, r.x, r.y, r.width, drop, static_cast<float>(rng.uniform(150.0, 220.0)));
  }
  if (rng.chance(0.6)) fill_rect(img, r.x + r.width / 2 - 2, r.y, 4, r.height, frame);
  if (rng.chance(0.4)) fill_rect(img, r.x, r.y + r.height / 3, r.width, 3, frame);
  fill_rect(img, r.x - 8, r.y + r.height + 4, r.width + 16, 6, frame + 15.0f);  // sill
}

void draw_bricks(cv::Mat& img, Random& rng) {
  const int bw = 12, bh = 4;  // 24 x 8 cm bricks at 2 cm per texel
  for (int row = 0; row * bh < img.rows; ++row) {
    const int offset = (row % 2) * bw / 2;
    for (int col = -1; col * bw < img.cols; ++col) {
      const float shade = static_cast<float>(rng.normal() * 14.0);
      add_rect(img, col * bw + offset + 1, row * bh + 1, bw - 1, bh - 1, shade);
      fill_rect(img, col * bw + offset, row * bh, 1, bh, 175.0f);  // mortar
    }
    fill_rect(img, 0, row * bh, img.cols, 1, 175.0f);
  }
}

}  // namespace

cv::Mat fractal_noise(int width, int height, int base_cell, int octaves, double persistence,
                      std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x6e6f697365));
  cv::Mat sum = cv::Mat::zeros(height, width, CV_32F);
  double amplitude = 1.0, total = 0.0;
  int cell = base_cell;
  for (int o = 0; o < octaves && cell >= 1; ++o, cell /= 2) {
    sum += noise_octave(width, height, cell, rng) * amplitude;
    total += amplitude;
    amplitude *= persistence;
  }
  return sum / total;
}

cv::Mat facade_texture(FacadeStyle style, std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xfacade));
  const int size = 1024, floors = 6, columns = 6;
  const double base = rng.uniform(110.0, 190.0);
  cv::Mat img = shaded_noise(size, size, 256, 7, 0.55, base, 22.0, rng.next());
  if (style == FacadeStyle::kBrick) draw_bricks(img, rng);
  const int cell_w = size / columns, cell_h = size / floors;
  if (style == FacadeStyle::kConcretePanels) {
    for (int i = 0; i <= columns * 2; ++i) fill_rect(img, i * cell_w / 2, 0, 2, size, base - 45);
    for (int j = 0; j <= floors; ++j) fill_rect(img, 0, j * cell_h, size, 3, base - 45);
  }
  // Stains and weathering: smooth dark streaks below the windows.
  img += shaded_noise(size, size, 128, 3, 0.5, 0.0, 12.0, rng.next());
  const float frame = static_cast<float>(style == FacadeStyle::kGlassOffice ? 60.0 : base + 40.0);
  const int win_w = style == FacadeStyle::kGlassOffice ? cell_w - 14 : rng.integer(55, 80);
  const int win_h = style == FacadeStyle::kGlassOffice ? cell_h - 30 : rng.integer(70, 95);
  for (int j = 0; j < floors; ++j) {
    for (int i = 0; i < columns; ++i) {
      const int x = i * cell_w + (cell_w - win_w) / 2;
      const int y = j * cell_h + (cell_h - win_h) / 2;
      draw_window(img, cv::Rect(x, y, win_w, win_h), frame, rng);
    }
    if (style != FacadeStyle::kGlassOffice)  // cornice between floors
      fill_rect(img, 0, j * cell_h + cell_h - 8, size, 5, static_cast<float>(base + 25.0));
  }
  img += fractal_noise(size, size, 4, 2, 0.5, rng.next()) * 8.0;  // fine grain
  return to_u8(img);
}

cv::Mat road_texture(bool with_arrows, std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x70ad));
  const int w = 1024, h = 512;  // 2.5 cm per texel: 40 texels per metre
  cv::Mat img = shaded_noise(w, h, 256, 5, 0.5, 95.0, 14.0, rng.next());
  img += fractal_noise(w, h, 4, 2, 0.6, rng.next()) * 10.0;  // asphalt grain
  for (int i = 0; i < 6; ++i) {                              // repaired patches
    const int pw = rng.integer(40, 200), ph = rng.integer(30, 120);
    add_rect(img, rng.integer(0, w - pw), rng.integer(0, h - ph), pw, ph,
             static_cast<float>(rng.uniform(-18.0, 12.0)));
  }
  for (int i = 0; i < 5; ++i) {  // cracks
    cv::Point p(rng.integer(0, w), rng.integer(0, h));
    for (int k = 0; k < 12; ++k) {
      const cv::Point q = p + cv::Point(rng.integer(-12, 12), rng.integer(-12, 12));
      cv::line(img, p, q, cv::Scalar(55), 1, cv::LINE_AA);
      p = q;
    }
  }
  const float paint = 215.0f;
  fill_rect(img, 0, 6, w, 6, paint);  // edge lines at 0.15 m and 12.65 m
  fill_rect(img, 0, h - 12, w, 6, paint);
  fill_rect(img, 0, h / 2 - 8, w, 5, paint);  // centre double line
  fill_rect(img, 0, h / 2 + 3, w, 5, paint);
  for (int k = 0; k < 4; ++k) {  // 3.2 m dashes every 6.4 m
    fill_rect(img, k * 256, h / 4 - 3, 128, 6, paint);
    fill_rect(img, k * 256 + 128, 3 * h / 4 - 3, 128, 6, paint);
  }
  if (with_arrows) {
    for (int lane = 0; lane < 4; ++lane) {
      const int cy = lane * h / 4 + h / 8;
      const int dir = lane >= 2 ? 1 : -1;  // lanes right of the centre drive along +u
      const int cx = 600;
      std::vector<cv::Point> arrow = {{cx - dir * 100, cy - 6}, {cx + dir * 40, cy - 6},
                                      {cx + dir * 40, cy - 22}, {cx + dir * 100, cy},
                                      {cx + dir * 40, cy + 22}, {cx + dir * 40, cy + 6},
                                      {cx - dir * 100, cy + 6}};
      cv::fillPoly(img, std::vector<std::vector<cv::Point>>{arrow}, cv::Scalar(paint), cv::LINE_AA);
    }
  }
  return to_u8(img);
}

cv::Mat intersection_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x1c));
  const int s = 1024;
  const double tpm = s / 24.0;  // texels per metre
  cv::Mat img = shaded_noise(s, s, 256, 5, 0.5, 95.0, 14.0, rng.next());
  img += fractal_noise(s, s, 4, 2, 0.6, rng.next()) * 10.0;
  const int band0 = static_cast<int>(1.0 * tpm), band1 = static_cast<int>(4.0 * tpm);
  for (int k = 0; k < 17; ++k) {  // zebra stripes, 50 cm wide, across the 17 m carriageway
    const int a = static_cast<int>((3.5 + k * 1.0) * tpm);
    const int wdt = static_cast<int>(0.5 * tpm);
    fill_rect(img, a, band0, wdt, band1 - band0, 210.0f);
    fill_rect(img, a, s - band1, wdt, band1 - band0, 210.0f);
    fill_rect(img, band0, a, band1 - band0, wdt, 210.0f);
    fill_rect(img, s - band1, a, band1 - band0, wdt, 210.0f);
  }
  return to_u8(img);
}

cv::Mat parking_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x9a4c));
  cv::Mat img = shaded_noise(512, 128, 128, 5, 0.5, 85.0, 12.0, rng.next());
  img += fractal_noise(512, 128, 4, 2, 0.6, rng.next()) * 10.0;
  fill_rect(img, 0, 0, 512, 4, 200.0f);
  for (int k = 0; k < 2; ++k) fill_rect(img, k * 256, 0, 5, 128, 200.0f);  // 6.4 m bays
  return to_u8(img);
}

cv::Mat sidewalk_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x51de));
  const int s = 512, tile = 16;
  cv::Mat img = shaded_noise(s, s, 128, 6, 0.5, 150.0, 12.0, rng.next());
  for (int ty = 0; ty < s / tile; ++ty)
    for (int tx = 0; tx < s / tile; ++tx) {
      add_rect(img, tx * tile, ty * tile, tile, tile, static_cast<float>(rng.normal() * 9.0));
      fill_rect(img, tx * tile, ty * tile, tile, 1, 95.0f);
      fill_rect(img, tx * tile, ty * tile, 1, tile, 95.0f);
    }
  return to_u8(img);
}

cv::Mat terrain_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x7e44));
  const int s = 512;
  cv::Mat img = shaded_noise(s, s, 128, 7, 0.65, 95.0, 40.0, rng.next());
  cv::Mat blades = fractal_noise(s, s, 4, 2, 0.5, rng.next());
  cv::threshold(blades, blades, 0.15, 1.0, cv::THRESH_BINARY);
  img += blades * 25.0;
  return to_u8(img);
}

cv::Mat rail_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x2a11));
  cv::Mat img = shaded_noise(256, 256, 64, 5, 0.5, 105.0, 20.0, rng.next());  // ballast
  img += fractal_noise(256, 256, 2, 2, 0.5, rng.next()) * 22.0;
  // Sleepers and two rails 1.43 m apart (40 texels per metre) in the first 3.2 m of rows.
  for (int x = 0; x < 256; x += 26) add_rect(img, x, 20, 10, 88, -35.0f);
  for (int y : {35, 92}) {
    fill_rect(img, 0, y, 256, 3, 215.0f);
    fill_rect(img, 0, y + 3, 256, 2, 60.0f);
  }
  return to_u8(img);
}

cv::Mat foliage_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xf011));
  const int s = 512;
  cv::Mat img = shaded_noise(s, s, 128, 4, 0.5, 55.0, 20.0, rng.next());
  for (int i = 0; i < 9000; ++i) {  // leaves: small bright ellipses over a dark crown
    const cv::Point c(rng.integer(0, s - 1), rng.integer(0, s - 1));
    const cv::Size axes(rng.integer(2, 6), rng.integer(1, 4));
    const double value = rng.uniform(60.0, 170.0);
    cv::ellipse(img, c, axes, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(value), -1, cv::LINE_AA);
  }
  return to_u8(img);
}

cv::Mat streaked_texture(int base_value, std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x57ea));
  cv::Mat img = shaded_noise(256, 256, 64, 5, 0.5, base_value, 10.0, rng.next());
  cv::Mat streaks = fractal_noise(256, 1, 16, 4, 0.6, rng.next());
  for (int y = 0; y < 256; ++y) img.row(y) += streaks * 25.0;
  return to_u8(img);
}

cv::Mat fence_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xfe2c));
  cv::Mat img = shaded_noise(512, 256, 128, 6, 0.5, 120.0, 15.0, rng.next());
  for (int x = 0; x < 512; x += 16) {
    add_rect(img, x, 0, 15, 256, static_cast<float>(rng.normal() * 15.0));
    fill_rect(img, x + 15, 0, 1, 256, 35.0f);  // gap between planks
  }
  fill_rect(img, 0, 40, 512, 10, 85.0f);  // rails
  fill_rect(img, 0, 200, 512, 10, 85.0f);
  return to_u8(img);
}

cv::Mat car_side_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xca2));
  const int w = 512, h = 256;
  const double body = rng.uniform(60.0, 200.0);
  cv::Mat img = shaded_noise(w, h, 128, 4, 0.5, body, 6.0, rng.next());
  // Windows on the upper part, split by pillars; a reflective gradient in the glass.
  for (int x = 70; x < 440; ++x)
    for (int y = 12; y < 100; ++y) img.at<float>(y, x) = 40.0f + 40.0f * static_cast<float>(x) / w;
  fill_rect(img, 200, 12, 10, 90, static_cast<float>(body - 30.0));
  fill_rect(img, 330, 12, 10, 90, static_cast<float>(body - 30.0));
  fill_rect(img, 0, 105, w, 3, static_cast<float>(body + 30.0));      // belt line
  fill_rect(img, 205, 105, 2, 110, static_cast<float>(body - 50.0));  // door seams
  fill_rect(img, 335, 105, 2, 110, static_cast<float>(body - 50.0));
  fill_rect(img, 250, 135, 30, 6, 170.0f);  // handles
  fill_rect(img, 380, 135, 30, 6, 170.0f);
  for (int cx : {100, 412}) {  // wheels and rims
    cv::circle(img, cv::Point(cx, h), 70, cv::Scalar(25), -1, cv::LINE_AA);
    cv::circle(img, cv::Point(cx, h), 38, cv::Scalar(150), -1, cv::LINE_AA);
    cv::circle(img, cv::Point(cx, h), 12, cv::Scalar(60), -1, cv::LINE_AA);
  }
  return to_u8(img);
}

cv::Mat car_end_texture(bool front, std::uint64_t seed) {
  Random rng(mix_seed(seed, front ? 0xf207 : 0x2ea2));
  const int s = 256;
  const double body = rng.uniform(60.0, 200.0);
  cv::Mat img = shaded_noise(s, s, 64, 4, 0.5, body, 6.0, rng.next());
  fill_rect(img, 20, 10, s - 40, 90, 55.0f);  // windscreen or rear window
  const float lamp = front ? 235.0f : 120.0f;
  fill_rect(img, 10, 125, 50, 25, lamp);
  fill_rect(img, s - 60, 125, 50, 25, lamp);
  if (front)
    for (int y = 130; y < 175; y += 8) fill_rect(img, 80, y, 96, 4, 40.0f);  // grille
  fill_rect(img, 88, 185, 80, 22, 225.0f);  // number plate with glyphs
  draw_text(img, random_text(rng, 5, 7), cv::Rect(90, 186, 76, 20), 20.0, cv::FONT_HERSHEY_SIMPLEX,
            1);
  fill_rect(img, 0, 215, s, 41, 35.0f);  // bumper and shadow
  return to_u8(img);
}

cv::Mat person_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x9e2));
  const int w = 128, h = 256;
  cv::Mat img = shaded_noise(w, h, 32, 4, 0.5, rng.uniform(40.0, 200.0), 12.0, rng.next());
  const float trousers = static_cast<float>(rng.uniform(30.0, 120.0));
  fill_rect(img, 0, 140, w, 116, trousers);
  fill_rect(img, w / 2 - 2, 150, 4, 106, trousers - 20.0f);  // legs apart
  fill_rect(img, 0, 0, w, 34, 45.0f);                        // hair
  cv::ellipse(img, cv::Point(w / 2, 24), cv::Size(20, 18), 0, 0, 360,
              cv::Scalar(rng.uniform(120.0, 200.0)), -1, cv::LINE_AA);  // face
  fill_rect(img, 0, 236, w, 20, 25.0f);                                 // shoes
  return to_u8(img);
}

cv::Mat sign_texture(int kind, std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x5164, static_cast<std::uint64_t>(kind)));
  const int s = 256;
  cv::Mat img(s, s, CV_32F, cv::Scalar(110));
  const cv::Point c(s / 2, s / 2);
  switch (kind % 4) {
    case 0:  // prohibition: red ring (dark in gray) around a white disc with a number
      cv::circle(img, c, 124, cv::Scalar(70), -1, cv::LINE_AA);
      cv::circle(img, c, 92, cv::Scalar(235), -1, cv::LINE_AA);
      draw_text(img, std::to_string(10 * rng.integer(2, 9)), cv::Rect(60, 70, 136, 116), 20.0,
                cv::FONT_HERSHEY_DUPLEX, 6);
      break;
    case 1: {  // warning triangle with a pictogram-like glyph
      std::vector<cv::Point> tri = {{128, 8}, {250, 240}, {6, 240}};
      cv::fillPoly(img, std::vector<std::vector<cv::Point>>{tri}, cv::Scalar(60), cv::LINE_AA);
      std::vector<cv::Point> inner = {{128, 50}, {215, 215}, {41, 215}};
      cv::fillPoly(img, std::vector<std::vector<cv::Point>>{inner}, cv::Scalar(230), cv::LINE_AA);
      draw_text(img, std::string(1, static_cast<char>('A' + rng.integer(0, 25))),
                cv::Rect(88, 120, 80, 80), 20.0, cv::FONT_HERSHEY_SIMPLEX, 8);
      break;
    }
    case 2:  // information panel with two lines of text
      img.setTo(cv::Scalar(60));
      cv::rectangle(img, cv::Rect(8, 8, s - 16, s - 16), cv::Scalar(225), 6);
      draw_text(img, random_text(rng, 4, 7), cv::Rect(20, 30, 216, 90), 230.0,
                cv::FONT_HERSHEY_SIMPLEX, 3);
      draw_text(img, random_text(rng, 3, 6), cv::Rect(20, 130, 216, 90), 230.0,
                cv::FONT_HERSHEY_SIMPLEX, 3);
      break;
    default: {  // direction: blue (mid gray) disc with a white arrow
      cv::circle(img, c, 124, cv::Scalar(85), -1, cv::LINE_AA);
      const int dir = rng.chance(0.5) ? 1 : -1;
      cv::arrowedLine(img, cv::Point(128 - dir * 70, 128), cv::Point(128 + dir * 75, 128),
                      cv::Scalar(240), 26, cv::LINE_AA, 0, 0.45);
    }
  }
  return to_u8(img);
}

cv::Mat traffic_light_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x7a1));
  cv::Mat img = shaded_noise(128, 256, 32, 3, 0.5, 40.0, 5.0, rng.next());
  const int lit = rng.integer(0, 2);
  for (int i = 0; i < 3; ++i) {
    const cv::Point c(64, 45 + 83 * i);
    cv::circle(img, c, 34, cv::Scalar(15), -1, cv::LINE_AA);  // visor shadow
    cv::circle(img, c, 27, cv::Scalar(i == lit ? 250 : 70), -1, cv::LINE_AA);
  }
  return to_u8(img);
}

cv::Mat shop_sign_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x5409));
  const bool dark = rng.chance(0.5);
  cv::Mat img = shaded_noise(512, 128, 64, 4, 0.5, dark ? 50.0 : 215.0, 8.0, rng.next());
  cv::rectangle(img, cv::Rect(3, 3, 506, 122), cv::Scalar(dark ? 200 : 40), 4);
  const int fonts[] = {cv::FONT_HERSHEY_SIMPLEX, cv::FONT_HERSHEY_DUPLEX, cv::FONT_HERSHEY_TRIPLEX,
                       cv::FONT_HERSHEY_COMPLEX};
  draw_text(img, random_text(rng, 4, 9), cv::Rect(12, 10, 488, 108), dark ? 235.0 : 25.0,
            fonts[rng.integer(0, 3)], rng.integer(2, 4));
  return to_u8(img);
}

cv::Mat poster_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x9057));
  const int s = 512;
  cv::Mat img = shaded_noise(s, s, 128, 4, 0.5, rng.uniform(120.0, 220.0), 25.0, rng.next());
  for (int i = 0; i < 14; ++i) {
    const cv::Point p(rng.integer(0, s), rng.integer(0, s));
    const cv::Scalar v(rng.uniform(10.0, 245.0));
    if (rng.chance(0.5))
      cv::circle(img, p, rng.integer(10, 70), v, -1, cv::LINE_AA);
    else
      cv::rectangle(img, cv::Rect(p.x, p.y, rng.integer(20, 150), rng.integer(20, 150)), v, -1);
  }
  for (int line = 0; line < 3; ++line)
    draw_text(img, random_text(rng, 5, 10), cv::Rect(20, 330 + 55 * line, 472, 50), 20.0,
              cv::FONT_HERSHEY_SIMPLEX, 2);
  cv::rectangle(img, cv::Rect(0, 0, s, s), cv::Scalar(240), 10);
  return to_u8(img);
}

cv::Mat floor_mat_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xf1002));
  const int s = 1024, mat = 128;  // 1.28 m mats at 1 cm per texel
  cv::Mat img = shaded_noise(s, s, 256, 6, 0.5, 0.0, 10.0, rng.next());
  for (int y = 0; y < s / mat; ++y)
    for (int x = 0; x < s / mat; ++x) {
      const float v = ((x + y) % 2 ? 60.0f : 150.0f) + static_cast<float>(rng.normal() * 12.0);
      add_rect(img, x * mat, y * mat, mat, mat, v);
      fill_rect(img, x * mat, y * mat, mat, 2, 30.0f);
      fill_rect(img, x * mat, y * mat, 2, mat, 30.0f);
    }
  for (int i = 0; i < 10; ++i)  // tape marks
    fill_rect(img, rng.integer(0, s), rng.integer(0, s), rng.integer(10, 90), 5, 220.0f);
  img += fractal_noise(s, s, 4, 2, 0.5, rng.next()) * 8.0;
  return to_u8(img);
}

cv::Mat ceiling_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0xce11));
  const int s = 512, tile = 32;
  cv::Mat img = shaded_noise(s, s, 128, 5, 0.5, 185.0, 8.0, rng.next());
  for (int y = 0; y < s / tile; ++y)
    for (int x = 0; x < s / tile; ++x) {
      fill_rect(img, x * tile, y * tile, tile, 2, 120.0f);
      fill_rect(img, x * tile, y * tile, 2, tile, 120.0f);
      if (rng.chance(0.06)) fill_rect(img, x * tile + 3, y * tile + 3, tile - 5, tile - 5, 250.0f);
    }
  return to_u8(img);
}

cv::Mat box_texture(bool crate, std::uint64_t seed) {
  Random rng(mix_seed(seed, crate ? 0xc2a7e : 0xca2d));
  const int s = 512;
  cv::Mat img = shaded_noise(s, s, 128, 6, 0.55, crate ? 150.0 : 135.0, 15.0, rng.next());
  if (crate) {
    for (int y = 0; y < s; y += 64) {
      add_rect(img, 0, y, s, 63, static_cast<float>(rng.normal() * 14.0));
      fill_rect(img, 0, y + 63, s, 2, 45.0f);
    }
    cv::rectangle(img, cv::Rect(0, 0, s, s), cv::Scalar(95), 40);
    cv::line(img, cv::Point(20, 20), cv::Point(s - 20, s - 20), cv::Scalar(95), 40);
  } else {
    fill_rect(img, s / 2 - 30, 0, 60, s, 175.0f);  // tape
    fill_rect(img, 0, s / 2 - 2, s, 4, 90.0f);     // flap seam
    draw_text(img, random_text(rng, 3, 6), cv::Rect(60, 330, 392, 120), 30.0,
              cv::FONT_HERSHEY_DUPLEX, 4);
    cv::rectangle(img, cv::Rect(80, 70, 130, 90), cv::Scalar(40), 5);
  }
  return to_u8(img);
}

cv::Mat wall_texture(std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x3a11));
  const int s = 512;
  cv::Mat img = shaded_noise(s, s, 256, 8, 0.6, rng.uniform(130.0, 190.0), 28.0, rng.next());
  if (rng.chance(0.5)) draw_bricks(img, rng);
  return to_u8(img);
}

cv::Mat marker_texture() {
  cv::Mat img(256, 256, CV_8U, cv::Scalar(0));
  // OpenCV draws pixel i at coordinate i, the centre of texel i, which is 127.5 here.
  cv::circle(img, cv::Point(2040, 2040), 64 * 16, cv::Scalar(255), -1, cv::LINE_AA, 4);
  return img;
}

cv::Mat photo_texture(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: texture photograph not found", path);
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) fail("{}: cannot decode the texture photograph", path);
  auto pow2 = [](int n) {
    int p = 16;
    while (p * 2 <= std::min(n, 1024)) p *= 2;
    return p;
  };
  cv::Mat out;
  cv::resize(img, out, cv::Size(pow2(img.cols), pow2(img.rows)), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace sbaslam::sim
