#include "sbaslam/core/lie.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

namespace sbaslam {
namespace {

class LieTest : public ::testing::Test {
 protected:
  std::mt19937 rng_{42};
  Vec3 random_vec3(double scale) {
    std::normal_distribution<double> n(0.0, scale);
    return Vec3(n(rng_), n(rng_), n(rng_));
  }
  // A rotation vector inside the ball of radius 3 so that log() returns it unchanged.
  Vec3 random_rotation_vector() {
    Vec3 phi = random_vec3(0.8);
    if (phi.norm() > 3.0) phi *= 3.0 / phi.norm();
    return phi;
  }
};

// Generic matrix exponential of the Lie algebra element, an independent reference.
Mat4 se3_hat(const Vec6& xi) {
  Mat4 m = Mat4::Zero();
  m.topLeftCorner<3, 3>() = hat(xi.tail<3>());
  m.topRightCorner<3, 1>() = xi.head<3>();
  return m;
}

Mat4 sim3_hat(const Vec7& z) {
  Mat4 m = Mat4::Zero();
  m.topLeftCorner<3, 3>() = hat(z.segment<3>(3)) + z(6) * Mat3::Identity();
  m.topRightCorner<3, 1>() = z.head<3>();
  return m;
}

TEST_F(LieTest, So3ExpMatchesRodrigues) {
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  const double angle = 0.7;
  const Mat3 expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  EXPECT_TRUE(SO3::exp(angle * axis).matrix().isApprox(expected, 1e-14));
}

TEST_F(LieTest, So3LogRoundTripIncludingNearPi) {
  for (int i = 0; i < 200; ++i) {
    Vec3 phi = random_vec3(1.0);
    if (phi.norm() > 3.1) phi *= 3.1 / phi.norm();
    EXPECT_TRUE(SO3::exp(phi).log().isApprox(phi, 1e-10)) << phi.transpose();
  }
  const Vec3 near_pi = (M_PI - 1e-9) * Vec3(0, 0, 1);
  EXPECT_NEAR(SO3::exp(near_pi).angle(), M_PI - 1e-9, 1e-9);
  const Vec3 tiny(1e-12, -2e-12, 3e-12);
  EXPECT_TRUE(SO3::exp(tiny).log().isApprox(tiny, 1e-6));
}

TEST_F(LieTest, Se3ExpMatchesMatrixExponential) {
  for (int i = 0; i < 100; ++i) {
    Vec6 xi;
    xi << random_vec3(2.0), random_rotation_vector();
    const Mat4 expected = se3_hat(xi).exp();
    EXPECT_TRUE(SE3::exp(xi).matrix().isApprox(expected, 1e-10));
    EXPECT_TRUE(SE3::exp(xi).log().isApprox(xi, 1e-9));
  }
  Vec6 small;
  small << 1e-3, 2e-3, -1e-3, 1e-9, -2e-9, 1e-9;
  EXPECT_TRUE(SE3::exp(small).matrix().isApprox(se3_hat(small).exp(), 1e-12));
}

TEST_F(LieTest, Sim3ExpMatchesMatrixExponential) {
  for (int i = 0; i < 100; ++i) {
    Vec7 z;
    z << random_vec3(2.0), random_rotation_vector(), random_vec3(0.5).x();
    const Mat4 expected = sim3_hat(z).exp();
    EXPECT_TRUE(Sim3::exp(z).matrix().isApprox(expected, 1e-10)) << z.transpose();
    EXPECT_TRUE(Sim3::exp(z).log().isApprox(z, 1e-9))
        << z.transpose() << " / " << Sim3::exp(z).log().transpose();
  }
  // Degenerate corners: no rotation, no scale, both.
  for (const Vec7& z : {(Vec7() << 1, 2, 3, 0, 0, 0, 0.3).finished(),
                        (Vec7() << 1, 2, 3, 0.2, -0.1, 0.3, 0).finished(),
                        (Vec7() << 1, 2, 3, 1e-9, 0, 0, 1e-9).finished()}) {
    EXPECT_TRUE(Sim3::exp(z).matrix().isApprox(sim3_hat(z).exp(), 1e-10)) << z.transpose();
  }
}

TEST_F(LieTest, ComposeInverseAndActAgree) {
  for (int i = 0; i < 50; ++i) {
    Vec6 a, b;
    a << random_vec3(1.0), random_vec3(0.5);
    b << random_vec3(1.0), random_vec3(0.5);
    const SE3 A = SE3::exp(a), B = SE3::exp(b);
    EXPECT_TRUE((A * B).matrix().isApprox(A.matrix() * B.matrix(), 1e-12));
    EXPECT_TRUE((A * A.inverse()).matrix().isApprox(Mat4::Identity(), 1e-12));
    const Vec3 p = random_vec3(3.0);
    EXPECT_TRUE((A * p).isApprox((A.matrix() * p.homogeneous()).head<3>(), 1e-12));

    const Sim3 S(1.7, A.so3(), A.translation());
    EXPECT_TRUE((S * S.inverse()).matrix().isApprox(Mat4::Identity(), 1e-12));
    EXPECT_TRUE((S * p).isApprox((S.matrix() * p.homogeneous()).head<3>(), 1e-12));
    EXPECT_TRUE(Sim3::from_matrix(S.matrix()).matrix().isApprox(S.matrix(), 1e-12));
  }
}

TEST_F(LieTest, InterpolationHitsEndpointsAndMidpoint) {
  const SE3 a(SO3::exp(Vec3(0, 0, 0.2)), Vec3(0, 0, 0));
  const SE3 b(SO3::exp(Vec3(0, 0, 0.6)), Vec3(2, 0, 0));
  EXPECT_TRUE(interpolate(a, b, 0.0).matrix().isApprox(a.matrix(), 1e-12));
  EXPECT_TRUE(interpolate(a, b, 1.0).matrix().isApprox(b.matrix(), 1e-12));
  const SE3 mid = interpolate(a, b, 0.5);
  EXPECT_NEAR(mid.so3().log().z(), 0.4, 1e-12);
  EXPECT_NEAR(mid.translation().x(), 1.0, 1e-12);
}

}  // namespace
}  // namespace sbaslam
