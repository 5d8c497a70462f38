#include "sbaslam/tracking/two_view_initializer.h"

#include <fmt/format.h>

#include <future>
#include <utility>

#include "sbaslam/core/error.h"
#include "sbaslam/geometry/motion_refinement.h"
#include "sbaslam/geometry/relative_pose.h"
#include "sbaslam/geometry/two_view_ransac.h"

namespace sbaslam::tracking {
namespace {

// What the motion candidates of the chosen model amount to.
struct Selection {
  int best = -1;
  int rival = -1;  // best-supported candidate that is a different motion
  std::vector<geometry::MotionSupport> support;
};

bool same_motion(const geometry::RelativeMotion& a, const geometry::RelativeMotion& b,
                 const TwoViewOptions& o) {
  return geometry::rotation_angle_deg(a.R21, b.R21) < o.same_motion_rotation_deg &&
         geometry::direction_angle_deg(a.t21, b.t21) < o.same_motion_direction_deg;
}

Selection select_motion(const std::vector<geometry::RelativeMotion>& motions,
                        const geometry::Correspondences& c, const std::vector<char>& inliers,
                        const PinholeIntrinsics& k, const TwoViewOptions& o) {
  Selection s;
  for (const geometry::RelativeMotion& m : motions) {
    s.support.push_back(geometry::check_motion(m, c, inliers, k, o.check));
    const int i = static_cast<int>(s.support.size()) - 1;
    if (s.best < 0 || s.support[i].good > s.support[s.best].good) s.best = i;
  }
  for (int i = 0; i < static_cast<int>(motions.size()); ++i) {
    if (i == s.best || same_motion(motions[i], motions[s.best], o)) continue;
    if (s.rival < 0 || s.support[i].good > s.support[s.rival].good) s.rival = i;
  }
  return s;
}

void refuse(TwoViewResult& r, TwoViewFailure why, std::string message) {
  r.failure = why;
  r.message = fmt::format("not initialised: {} ({})", to_string(why), message);
}

geometry::Correspondences build_correspondences(const std::vector<feature::OrbKeypoint>& kp1,
                                                const std::vector<feature::OrbKeypoint>& kp2,
                                                const std::vector<match::Match>& matches,
                                                const feature::ScaleLevels& levels) {
  geometry::Correspondences c;
  auto inv_sigma2 = [&](const feature::OrbKeypoint& kp, int view) {
    if (kp.octave < 0 || kp.octave >= levels.size())
      fail("two-view initialisation: keypoint octave {} in view {} outside the {} pyramid levels",
           kp.octave, view, levels.size());
    return static_cast<double>(levels.inv_sigma2[kp.octave]);
  };
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const match::Match& m = matches[i];
    if (m.query < 0 || m.query >= static_cast<int>(kp1.size()) || m.train < 0 ||
        m.train >= static_cast<int>(kp2.size()))
      fail("two-view initialisation: match {} ({} -> {}) outside the keypoints ({} and {})", i,
           m.query, m.train, kp1.size(), kp2.size());
    const feature::OrbKeypoint &a = kp1[m.query], &b = kp2[m.train];
    c.add(Vec2(a.x, a.y), Vec2(b.x, b.y), inv_sigma2(a, 1), inv_sigma2(b, 2));
  }
  return c;
}

void accept(const geometry::RelativeMotion& motion, const geometry::MotionSupport& support,
            TwoViewResult& r) {
  r.failure = TwoViewFailure::kNone;
  r.R21 = motion.R21;
  r.t21 = motion.t21;
  r.points = support.points;
  r.triangulated = support.valid;
  r.triangulated_count = support.triangulated;
  r.parallax_deg = support.parallax_deg;
  r.median_parallax_deg = support.median_parallax_deg;
  r.message = fmt::format("initialised from the {}: {} points, parallax {:.2f} deg",
                          to_string(r.model), support.triangulated, support.parallax_deg);
}

struct Chosen {
  geometry::RelativeMotion motion;
  geometry::MotionSupport support;
};

// The best candidate, refined unless that loses over a tenth of its support (the gates move a few
// boundary points either way; the guard catches a diverged solve). The linear motion of an 8-point
// model fits the noise of its sample: refining before the checks below lets a correct but imprecise
// motion pass the reprojection gate.
Chosen refine_best(const std::vector<geometry::RelativeMotion>& motions, const Selection& s,
                   bool use_h, const Mat3& H21, const geometry::Correspondences& c,
                   const std::vector<char>& inliers, const PinholeIntrinsics& k,
                   const TwoViewOptions& o) {
  Chosen out{motions[s.best], s.support[s.best]};
  if (!o.refine) return out;
  // On a plane the epipolar constraint leaves the motion unconstrained: refine the homography.
  const geometry::RelativeMotion refined =
      use_h ? geometry::refine_plane_motion(out.motion, H21, c, k)
            : geometry::refine_motion(out.motion, c, k);
  geometry::MotionSupport after = geometry::check_motion(refined, c, inliers, k, o.check);
  if (after.good >= 0.9 * out.support.good) out = {refined, std::move(after)};
  return out;
}

// Accepts the chosen motion or says why not. The rivals were checked unrefined, so the clear-
// winner test compares them with the unrefined best.
void decide(const Chosen& chosen, const Selection& s, int model_inliers, double rival_ratio,
            const TwoViewOptions& o, TwoViewResult& r) {
  const geometry::MotionSupport& best = chosen.support;
  const int linear_best = s.support[s.best].good;
  r.best_support = best.good;
  r.rival_support = s.rival >= 0 ? s.support[s.rival].good : 0;
  r.parallax_deg = best.parallax_deg;
  r.median_parallax_deg = best.median_parallax_deg;
  r.triangulated_count = best.triangulated;
  if (best.parallax_deg < o.min_parallax_deg)
    return refuse(
        r, TwoViewFailure::kLowParallax,
        fmt::format("parallax {:.2f} deg < {:.2f} deg", best.parallax_deg, o.min_parallax_deg));
  if (best.triangulated < o.min_triangulated)
    return refuse(
        r, TwoViewFailure::kTooFewTriangulated,
        fmt::format("{} points triangulated < {}", best.triangulated, o.min_triangulated));
  if (best.good < o.min_supported_fraction * model_inliers)
    return refuse(r, TwoViewFailure::kTooFewTriangulated,
                  fmt::format("the motion explains {} of {} inliers", best.good, model_inliers));
  if (r.rival_support >= rival_ratio * linear_best)
    return refuse(r, TwoViewFailure::kAmbiguous,
                  fmt::format("a different motion explains {} matches against {}", r.rival_support,
                              linear_best));
  accept(chosen.motion, best, r);
}

}  // namespace

std::string_view to_string(TwoViewModel model) {
  switch (model) {
    case TwoViewModel::kHomography:
      return "homography";
    case TwoViewModel::kFundamental:
      return "fundamental";
    case TwoViewModel::kNone:
      break;
  }
  return "none";
}

std::string_view to_string(TwoViewFailure failure) {
  switch (failure) {
    case TwoViewFailure::kNone:
      return "initialised";
    case TwoViewFailure::kTooFewMatches:
      return "too few matches";
    case TwoViewFailure::kTooFewInliers:
      return "too few inliers";
    case TwoViewFailure::kLowParallax:
      return "insufficient parallax";
    case TwoViewFailure::kTooFewTriangulated:
      return "too few triangulated points";
    case TwoViewFailure::kAmbiguous:
      return "ambiguous motion";
  }
  return "unknown";
}

void validate(const TwoViewOptions& o) {
  auto require = [](bool ok, const char* name, double value) {
    if (!ok) fail("two-view options: {} = {} is out of range", name, value);
  };
  require(o.ransac_iterations >= 1, "ransac_iterations", o.ransac_iterations);
  require(o.min_matches >= 8, "min_matches", o.min_matches);
  require(o.min_triangulated >= 1, "min_triangulated", o.min_triangulated);
  require(o.min_parallax_deg >= 0.0, "min_parallax_deg", o.min_parallax_deg);
  require(o.homography_ratio > 0.0 && o.homography_ratio < 1.0, "homography_ratio",
          o.homography_ratio);
  require(o.min_supported_fraction >= 0.0 && o.min_supported_fraction <= 1.0,
          "min_supported_fraction", o.min_supported_fraction);
  require(o.homography_rival_ratio > 0.0 && o.homography_rival_ratio <= 1.0,
          "homography_rival_ratio", o.homography_rival_ratio);
  require(o.fundamental_rival_ratio > 0.0 && o.fundamental_rival_ratio <= 1.0,
          "fundamental_rival_ratio", o.fundamental_rival_ratio);
  require(o.check.reprojection_chi2 > 0.0, "check.reprojection_chi2", o.check.reprojection_chi2);
}

TwoViewInitializer::TwoViewInitializer(const PinholeIntrinsics& k, feature::ScaleLevels levels,
                                       TwoViewOptions options)
    : k_(k), levels_(std::move(levels)), options_(std::move(options)) {
  validate(options_);
  if (!(k_.fx > 0.0 && k_.fy > 0.0))
    fail("two-view initialisation: focal lengths must be positive (fx {}, fy {})", k_.fx, k_.fy);
  if (levels_.size() == 0) fail("two-view initialisation: no pyramid levels");
}

TwoViewResult TwoViewInitializer::initialize(const std::vector<feature::OrbKeypoint>& keypoints1,
                                             const std::vector<feature::OrbKeypoint>& keypoints2,
                                             const std::vector<match::Match>& matches,
                                             std::uint64_t seed) const {
  const TwoViewOptions& o = options_;
  const geometry::Correspondences c =
      build_correspondences(keypoints1, keypoints2, matches, levels_);
  TwoViewResult r;
  if (c.size() < o.min_matches) {
    refuse(r, TwoViewFailure::kTooFewMatches, fmt::format("{} < {}", c.size(), o.min_matches));
    return r;
  }

  const auto sets = geometry::sample_minimal_sets(c.size(), o.ransac_iterations, seed);
  const auto policy = o.parallel ? std::launch::async : std::launch::deferred;
  auto future_h = std::async(policy, [&] { return geometry::ransac_homography(c, sets); });
  const geometry::ModelFit fit_f = geometry::ransac_fundamental(c, sets);
  const geometry::ModelFit fit_h = future_h.get();

  r.H21 = fit_h.model;
  r.F21 = fit_f.model;
  r.score_h = fit_h.score.score;
  r.score_f = fit_f.score.score;
  r.inliers_h = fit_h.score.inlier_count;
  r.inliers_f = fit_f.score.inlier_count;
  const double total = r.score_h + r.score_f;
  r.ratio_h = total > 0.0 ? r.score_h / total : 0.0;
  const bool use_h = r.ratio_h > o.homography_ratio;
  reconstruct(use_h ? TwoViewModel::kHomography : TwoViewModel::kFundamental, use_h ? fit_h : fit_f,
              c, r);
  // A plane seen with noise can outscore its homography with a (degenerate) fundamental matrix;
  // that F then fails the checks above. The homography's own checks guard the retry.
  if (!r.ok() && !use_h && o.fallback_to_homography) {
    TwoViewResult retry = r;
    reconstruct(TwoViewModel::kHomography, fit_h, c, retry);
    if (retry.ok()) {
      retry.message += fmt::format(" after the fundamental matrix failed: {}", r.message);
      return retry;
    }
  }
  return r;
}

void TwoViewInitializer::reconstruct(TwoViewModel model, const geometry::ModelFit& fit,
                                     const geometry::Correspondences& c, TwoViewResult& r) const {
  const TwoViewOptions& o = options_;
  const bool use_h = model == TwoViewModel::kHomography;
  r.model = model;
  if (fit.score.inlier_count < o.min_triangulated)
    return refuse(r, TwoViewFailure::kTooFewInliers,
                  fmt::format("{} {} inliers of {} matches < {}", fit.score.inlier_count,
                              to_string(model), c.size(), o.min_triangulated));
  std::vector<geometry::RelativeMotion> motions;
  if (use_h) {
    const geometry::HomographyDecomposition d = geometry::decompose_homography(fit.model, k_);
    if (d.pure_rotation)
      return refuse(r, TwoViewFailure::kLowParallax, "the homography is a pure rotation");
    motions = d.motions;
  } else {
    motions = geometry::decompose_essential(geometry::essential_from_fundamental(fit.model, k_));
  }
  const Selection s = select_motion(motions, c, fit.score.inliers, k_, o);
  const double rival_ratio = use_h ? o.homography_rival_ratio : o.fundamental_rival_ratio;
  const Chosen chosen = refine_best(motions, s, use_h, fit.model, c, fit.score.inliers, k_, o);
  decide(chosen, s, fit.score.inlier_count, rival_ratio, o, r);
}

}  // namespace sbaslam::tracking
