// SPDX-License-Identifier: BSD-3-Clause
// Rigid registration (Kabsch/Umeyama): exact recovery of seeded random transforms, the residual
// and the estimate error under Gaussian noise against their expected values (theory §11), the
// reflection fix, degenerate inputs, frame-swap and change-of-frame invariance, and agreement
// with two independent methods written here (Horn's quaternion closed form, Gauss-Newton).
// Case counts scale with HEXATWIST_STRESS (support.hpp).
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <vector>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The largest of the values passed through it, reported when the test ends.
class Worst {
 public:
  explicit Worst(const char* what) : what_(what) {}
  ~Worst() { report(what_, value_); }
  Worst(const Worst&) = delete;
  Worst& operator=(const Worst&) = delete;
  double operator()(double v) {
    value_ = std::max(value_, v);
    return v;
  }

 private:
  const char* what_;
  double value_ = 0.0;
};

double gaussian(std::mt19937_64& rng) { return std::normal_distribution<double>(0.0, 1.0)(rng); }

// Uniformly distributed rotation (normalised Gaussian quaternion).
Matrix3d random_rotation(std::mt19937_64& rng) {
  Eigen::Quaterniond q(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
  return q.normalized().toRotationMatrix();
}

// A tracker pose in the base frame: any orientation, up to `reach` metres away.
RigidTransform random_transform(std::mt19937_64& rng, double reach = 8.0) {
  return {random_rotation(rng),
          Vector3d(uniform(rng, -reach, reach), uniform(rng, -reach, reach), uniform(rng, -reach, reach))};
}

// Observation-point-like positions above the base [m, B], or all at one height if `planar`;
// thin sets (second principal spread below a tenth of the first, which three random points
// sometimes are) are drawn again: the degenerate ones have tests of their own.
std::vector<Vector3d> random_points_B(std::mt19937_64& rng, int n, bool planar = false) {
  std::vector<Vector3d> p(static_cast<std::size_t>(n));
  for (;;) {
    for (Vector3d& v : p) {
      v = Vector3d(uniform(rng, -0.6, 0.6), uniform(rng, -0.6, 0.6), planar ? 1.5 : uniform(rng, 1.0, 2.0));
    }
    Vector3d c = Vector3d::Zero();
    for (const Vector3d& v : p) c += v / n;
    Matrix3d M = Matrix3d::Zero();
    for (const Vector3d& v : p) M += (v - c) * (v - c).transpose();
    const Vector3d lambda = Eigen::SelfAdjointEigenSolver<Matrix3d>(M).eigenvalues();  // ascending
    if (lambda[1] >= 1e-2 * lambda[2]) return p;
  }
}

// The pairs a tracker at X_BT would record for the base points, with Gaussian noise sigma [m]
// on each tracker coordinate.
std::vector<PointPair> pairs_for(const RigidTransform& X_BT, const std::vector<Vector3d>& points_B, double sigma,
                                 std::mt19937_64& rng) {
  const RigidTransform X_TB = inverse(X_BT);
  std::vector<PointPair> pairs;
  for (const Vector3d& p_B : points_B) {
    const Vector3d noise(gaussian(rng), gaussian(rng), gaussian(rng));
    pairs.push_back({apply(X_TB, p_B) + sigma * noise, p_B});
  }
  return pairs;
}

std::vector<PointPair> swapped(const std::vector<PointPair>& pairs) {
  std::vector<PointPair> out;
  for (const PointPair& p : pairs) out.push_back({p.p_B, p.p_T});
  return out;
}

// Small rotation vector w with R_a = exp(w)·R_b [rad, in the frame R_a maps into].
Vector3d rotation_difference(const Matrix3d& R_a, const Matrix3d& R_b) {
  const Eigen::AngleAxisd aa(R_a * R_b.transpose());
  return aa.angle() * aa.axis();
}
double rotation_error(const Matrix3d& R_a, const Matrix3d& R_b) { return rotation_difference(R_a, R_b).norm(); }

// Horn (1987): the unit quaternion that maximises Σ b_k·(q a_k q*) is the eigenvector of the
// largest eigenvalue of a symmetric 4x4 built from S = Σ a_k b_kᵀ (a, b centred). Independent
// of the SVD, and it searches proper rotations only.
Matrix3d horn_rotation(const std::vector<PointPair>& pairs) {
  Vector3d c_T = Vector3d::Zero(), c_B = Vector3d::Zero();
  for (const PointPair& p : pairs) c_T += p.p_T, c_B += p.p_B;
  c_T /= static_cast<double>(pairs.size());
  c_B /= static_cast<double>(pairs.size());
  Matrix3d S = Matrix3d::Zero();
  for (const PointPair& p : pairs) S += (p.p_T - c_T) * (p.p_B - c_B).transpose();
  const double xx = S(0, 0), xy = S(0, 1), xz = S(0, 2), yx = S(1, 0), yy = S(1, 1), yz = S(1, 2), zx = S(2, 0),
               zy = S(2, 1), zz = S(2, 2);
  Eigen::Matrix4d N;
  N << xx + yy + zz, yz - zy, zx - xz, xy - yx,  //
      yz - zy, xx - yy - zz, xy + yx, zx + xz,   //
      zx - xz, xy + yx, -xx + yy - zz, yz + zy,  //
      xy - yx, zx + xz, yz + zy, -xx - yy + zz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(N);
  const Eigen::Vector4d q = es.eigenvectors().col(3);  // eigenvalues ascending
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

// Gauss-Newton on Σ|R p_T + t − p_B|² from `X`, perturbing t += dt, R = exp(dw)·R: an iterative
// answer that shares nothing with the closed forms (no centroids, no SVD, no eigenvectors).
RigidTransform gauss_newton(const std::vector<PointPair>& pairs, RigidTransform X) {
  for (int it = 0; it < 100; ++it) {
    Matrix6d JtJ = Matrix6d::Zero();
    Vector6d Jte = Vector6d::Zero();
    for (const PointPair& p : pairs) {
      const Vector3d Rp = X.R * p.p_T;
      Eigen::Matrix<double, 3, 6> J;
      J.leftCols<3>().setIdentity();
      J.rightCols<3>() << 0, Rp.z(), -Rp.y(), -Rp.z(), 0, Rp.x(), Rp.y(), -Rp.x(), 0;  // d(Rp)/dw = −[Rp]×
      JtJ += J.transpose() * J;
      Jte += J.transpose() * (Rp + X.t - p.p_B);
    }
    const Vector6d dx = -JtJ.ldlt().solve(Jte);
    X.t += dx.head<3>();
    X.R = exp_so3(dx.tail<3>()) * X.R;
    if (dx.norm() < 1e-15) break;
  }
  return X;
}

double sum_squared_residual(const std::vector<PointPair>& pairs, const RigidTransform& X) {
  double s = 0.0;
  for (const PointPair& p : pairs) s += (apply(X, p.p_T) - p.p_B).squaredNorm();
  return s;
}

std::string str(const RigidTransform& X) {
  std::ostringstream os;
  os.precision(17);
  os << "R = [" << X.R.row(0) << "; " << X.R.row(1) << "; " << X.R.row(2) << "], t = [" << X.t.transpose() << "]";
  return os.str();
}

TEST(Registration, RecoversRandomTransformsWithoutNoise) {
  std::mt19937_64 rng(kSeed + 1100);
  Worst rot("rotation error [rad]"), pos("translation error [m] (tracker up to 14 m away)"),
      max_res("max residual [m]"), det("|det R − 1|");
  const int cases = stress(3000);
  for (int c = 0; c < cases; ++c) {
    const int n = 3 + static_cast<int>(uniform(rng, 0, 60));
    const RigidTransform X = random_transform(rng);
    const std::vector<PointPair> pairs = pairs_for(X, random_points_B(rng, n), 0.0, rng);
    Registration r;
    ASSERT_EQ(register_points(pairs, r), Status::Ok) << "N " << n << ", " << str(X);
    SCOPED_TRACE("N " + std::to_string(n) + ", true " + str(X) + ", found " + str(r.X_BT));
    ASSERT_EQ(r.count, n);
    ASSERT_LT(rot(rotation_error(r.X_BT.R, X.R)), 4e-14);
    ASSERT_LT(pos((r.X_BT.t - X.t).norm()), 4e-13);
    ASSERT_LT(max_res(r.max_residual), 1e-13);
    ASSERT_LE(r.rms_residual, r.max_residual);
    ASSERT_LT(det(std::abs(r.X_BT.R.determinant() - 1.0)), 4e-14);
    // Four or more random points are not coplanar, so no reflection fix was needed.
    if (n >= 4) {
      ASSERT_FALSE(r.reflection);
    }
  }
}

TEST(Registration, CoplanarPointsNeedTheReflectionFixAndStillRecoverTheTransform) {
  // Coplanar points leave the third singular vector's sign to rounding, so V·Uᵀ is a reflection
  // about half the time even without noise; the fix must recover the rotation every time.
  std::mt19937_64 rng(kSeed + 1101);
  int reflections = 0;
  Worst rot("coplanar: rotation error [rad]"), pos("coplanar: translation error [m]");
  const int cases = stress(1000);
  for (int c = 0; c < cases; ++c) {
    const int n = 3 + static_cast<int>(uniform(rng, 0, 20));
    const std::vector<Vector3d> points = random_points_B(rng, n, true);
    const RigidTransform X = random_transform(rng);
    Registration r;
    ASSERT_EQ(register_points(pairs_for(X, points, 0.0, rng), r), Status::Ok);
    reflections += r.reflection ? 1 : 0;
    ASSERT_LT(rot(rotation_error(r.X_BT.R, X.R)), 1e-13) << "N " << n << ", " << str(X);
    ASSERT_LT(pos((r.X_BT.t - X.t).norm()), 1e-12) << "N " << n << ", " << str(X);
  }
  std::printf("  coplanar: reflection fix applied in %d of %d cases\n", reflections, cases);
  EXPECT_GT(reflections, cases / 5);  // the case is really exercised
}

TEST(Registration, MirroredPointsGiveTheBestProperRotation) {
  // The tracker frame is mirrored (one axis flipped), so the best orthogonal map is a reflection.
  std::mt19937_64 rng(kSeed + 1102);
  Worst det("mirrored: |det R − 1|"), orth("mirrored: |RᵀR − I|"), horn("mirrored: rotation difference to Horn [rad]"),
      rms("mirrored: relative rms difference to a direct sum");
  for (int c = 0; c < stress(200); ++c) {
    const RigidTransform X = random_transform(rng);
    // Spreads about 0.35, 0.17 and 0.06 m, so that flipping the smallest direction is well
    // defined (the rotation's weakest Hessian eigenvalue is h2 − h3, theory §11).
    std::vector<Vector3d> points = random_points_B(rng, 12);
    for (Vector3d& p : points) p = Vector3d(p.x(), 0.5 * p.y(), 1.0 + 0.2 * (p.z() - 1.0));
    std::vector<PointPair> pairs = pairs_for(X, points, 1e-5, rng);
    for (PointPair& p : pairs) p.p_T.x() = -p.p_T.x();
    Registration r;
    ASSERT_EQ(register_points(pairs, r), Status::Ok) << str(X);
    SCOPED_TRACE(str(r.X_BT));
    EXPECT_TRUE(r.reflection);
    EXPECT_LT(det(std::abs(r.X_BT.R.determinant() - 1.0)), 4e-14);
    EXPECT_LT(orth((r.X_BT.R.transpose() * r.X_BT.R - Matrix3d::Identity()).cwiseAbs().maxCoeff()), 3e-14);
    // Horn's method maximises over rotations only: the same optimum.
    EXPECT_LT(horn(rotation_error(r.X_BT.R, horn_rotation(pairs))), 2e-13);
    // And no nearby rotation (with its best translation) fits better.
    const double best = sum_squared_residual(pairs, r.X_BT);
    EXPECT_LT(rms(std::abs(r.rms_residual / std::sqrt(best / 12.0) - 1.0)), 3e-15);
    for (int k = 0; k < 20; ++k) {
      const Vector3d w(uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3));
      RigidTransform Y = r.X_BT;
      Y.R = exp_so3(w) * Y.R;
      Vector3d shift = Vector3d::Zero();
      for (const PointPair& p : pairs) shift += p.p_B - apply(Y, p.p_T);
      Y.t += shift / 12.0;
      EXPECT_GT(sum_squared_residual(pairs, Y), best) << "perturbation " << w.transpose();
    }
  }
}

TEST(Registration, ResidualMatchesTheNoiseLevel) {
  // Isotropic Gaussian noise sigma per coordinate: Σ|e|² ~ sigma² χ²(3N − 6), so the rms of the
  // 3-D residual distances has E[rms²] = 3 sigma² (3N − 6)/(3N) (per coordinate:
  // sigma² (3N − 6)/(3N)) and E[Registration::sigma²] = sigma² (theory §11).
  const double sigma = 10e-6;  // the tracker class of the paper
  const int seeds = stress(500);
  std::mt19937_64 rng(kSeed + 1103);
  for (const int n : {3, 4, 12, 40}) {
    const double dof = 3.0 * n - 6.0;
    double mean_rms2 = 0.0, mean_sigma2 = 0.0;
    for (int s = 0; s < seeds; ++s) {
      Registration r;
      ASSERT_EQ(register_points(pairs_for(random_transform(rng), random_points_B(rng, n), sigma, rng), r), Status::Ok);
      mean_rms2 += r.rms_residual * r.rms_residual / seeds;
      mean_sigma2 += r.sigma * r.sigma / seeds;
    }
    const double expected_rms2 = 3.0 * sigma * sigma * dof / (3.0 * n);
    // The mean of `seeds` draws of χ²(dof)/dof has a relative standard deviation sqrt(2/(dof·seeds)).
    const double tol = 4.0 * std::sqrt(2.0 / (dof * seeds));
    std::printf("  N %2d: rms %.3g m, mean rms² / expected %.4f, mean sigma² / sigma² %.4f (tolerance ±%.3f)\n", n,
                std::sqrt(mean_rms2), mean_rms2 / expected_rms2, mean_sigma2 / (sigma * sigma), tol);
    EXPECT_NEAR(mean_rms2 / expected_rms2, 1.0, tol) << "N " << n;
    EXPECT_NEAR(mean_sigma2 / (sigma * sigma), 1.0, tol) << "N " << n;
  }
}

// Squared rotation error predicted to first order for noise sigma on the tracker coordinates:
// E|w|² = sigma² tr((tr(M) I − M)⁻¹), M = Σ b bᵀ over the centred base points (theory §11).
double predicted_rotation_error2(const std::vector<Vector3d>& points_B, double sigma) {
  Vector3d c = Vector3d::Zero();
  for (const Vector3d& p : points_B) c += p;
  c /= static_cast<double>(points_B.size());
  Matrix3d M = Matrix3d::Zero();
  for (const Vector3d& p : points_B) M += (p - c) * (p - c).transpose();
  return sigma * sigma * (M.trace() * Matrix3d::Identity() - M).inverse().trace();
}

Vector3d centroid(const std::vector<Vector3d>& points) {
  Vector3d c = Vector3d::Zero();
  for (const Vector3d& p : points) c += p;
  return c / static_cast<double>(points.size());
}

TEST(Registration, EstimateErrorMatchesItsPredictedCovariance) {
  // The rotation error w (R_found = exp(w) R_true) against its first-order covariance, and the
  // registered centroid, off by the mean noise: E|.|² = 3 sigma²/N.
  const double sigma = 10e-6;
  const int seeds = stress(1000);
  std::mt19937_64 rng(kSeed + 1104);
  for (const int n : {4, 8, 32, 128}) {
    double rot_ratio = 0.0, pos_ratio = 0.0;
    for (int s = 0; s < seeds; ++s) {
      const RigidTransform X = random_transform(rng);
      const std::vector<Vector3d> points = random_points_B(rng, n);
      const Vector3d c = centroid(points);
      Registration r;
      ASSERT_EQ(register_points(pairs_for(X, points, sigma, rng), r), Status::Ok);
      rot_ratio += rotation_difference(r.X_BT.R, X.R).squaredNorm() / predicted_rotation_error2(points, sigma) / seeds;
      pos_ratio += (apply(r.X_BT, apply(inverse(X), c)) - c).squaredNorm() / (3.0 * sigma * sigma / n) / seeds;
    }
    // A mean of `seeds` squared errors over three (correlated) axes: relative standard deviation
    // at most sqrt(2/seeds); the tolerance is four of them.
    const double tol = 4.0 * std::sqrt(2.0 / seeds);
    std::printf("  N %3d: mean square / predicted: rotation %.3f, centroid %.3f (tolerance ±%.3f)\n", n, rot_ratio,
                pos_ratio, tol);
    EXPECT_NEAR(rot_ratio, 1.0, tol) << "N " << n;
    EXPECT_NEAR(pos_ratio, 1.0, tol) << "N " << n;
  }
}

TEST(Registration, EstimateErrorHalvesWithFourTimesTheMeasurements) {
  // Eight stations, each measured N/8 times with independent noise: the same stations and
  // transforms for every N, so only N changes and the rms errors must fall as 1/sqrt(N).
  const double sigma = 10e-6;
  const int seeds = stress(2000);
  std::mt19937_64 noise(kSeed + 1114);
  double previous_rot = 0.0, previous_pos = 0.0;
  for (const int n : {8, 32, 128, 512}) {
    std::mt19937_64 rng(kSeed + 1115);
    double rot2 = 0.0, pos2 = 0.0;
    for (int s = 0; s < seeds; ++s) {
      const RigidTransform X = random_transform(rng);
      const std::vector<Vector3d> stations = random_points_B(rng, 8);
      std::vector<Vector3d> points;
      for (int k = 0; k < n / 8; ++k) points.insert(points.end(), stations.begin(), stations.end());
      const Vector3d c = centroid(stations);
      Registration r;
      ASSERT_EQ(register_points(pairs_for(X, points, sigma, noise), r), Status::Ok);
      rot2 += rotation_difference(r.X_BT.R, X.R).squaredNorm() / seeds;
      pos2 += (apply(r.X_BT, apply(inverse(X), c)) - c).squaredNorm() / seeds;
    }
    const double rms_rot = std::sqrt(rot2), rms_pos = std::sqrt(pos2);
    std::printf("  N %3d: rms rotation error %.3g rad, rms centroid error %.3g m\n", n, rms_rot, rms_pos);
    if (previous_rot > 0.0) {
      // Each rms from `seeds` draws has a relative standard deviation of at most sqrt(1/(2 seeds));
      // their ratio at most sqrt(1/seeds). The tolerance is four of them, on a ratio of 2.
      const double tol = 2.0 * 4.0 * std::sqrt(1.0 / seeds);
      std::printf("         ratio to N/4: rotation %.3f, centroid %.3f (tolerance 2 ± %.3f)\n", previous_rot / rms_rot,
                  previous_pos / rms_pos, tol);
      EXPECT_NEAR(previous_rot / rms_rot, 2.0, tol) << "N " << n;
      EXPECT_NEAR(previous_pos / rms_pos, 2.0, tol) << "N " << n;
    }
    previous_rot = rms_rot;
    previous_pos = rms_pos;
  }
}

TEST(Registration, AgreesWithHornQuaternionAndGaussNewton) {
  // Noise from none to 1 cm, and a few gross outliers: the least-squares optimum is the same
  // whichever way it is computed. Gauss-Newton starts 0.2 rad and 10 cm away from the truth.
  std::mt19937_64 rng(kSeed + 1105);
  Worst horn("rotation difference to Horn's quaternion [rad]"), gn_rot("rotation difference to Gauss-Newton [rad]"),
      gn_pos("translation difference to Gauss-Newton [m]");
  for (int c = 0; c < stress(2000); ++c) {
    const int n = 3 + static_cast<int>(uniform(rng, 0, 40));
    const double sigma = std::pow(10.0, uniform(rng, -7, -2));
    const RigidTransform X = random_transform(rng);
    std::vector<PointPair> pairs = pairs_for(X, random_points_B(rng, n), sigma, rng);
    if (c % 4 == 0) pairs[static_cast<std::size_t>(c) % pairs.size()].p_B.x() += 0.05;
    Registration r;
    ASSERT_EQ(register_points(pairs, r), Status::Ok);
    SCOPED_TRACE("N " + std::to_string(n) + ", sigma " + std::to_string(sigma) + ", " + str(r.X_BT));
    const Vector3d w = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized() * 0.2;
    const Vector3d dt = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized() * 0.1;
    const RigidTransform G = gauss_newton(pairs, {exp_so3(w) * X.R, X.t + dt});
    ASSERT_LT(horn(rotation_error(r.X_BT.R, horn_rotation(pairs))), 1.5e-13);
    ASSERT_LT(gn_rot(rotation_error(r.X_BT.R, G.R)), 2e-13);
    ASSERT_LT(gn_pos((r.X_BT.t - G.t).norm()), 6e-13);
  }
}

TEST(Registration, SwappingTheFramesGivesTheInverseTransform) {
  std::mt19937_64 rng(kSeed + 1106);
  Worst rot("forward∘swapped registration, rotation from identity [rad]"),
      pos("forward∘swapped registration, translation from zero [m]"), rms("rms residual difference [m]");
  for (int c = 0; c < stress(1000); ++c) {
    const int n = 3 + static_cast<int>(uniform(rng, 0, 30));
    const std::vector<PointPair> pairs = pairs_for(random_transform(rng), random_points_B(rng, n), 1e-4, rng);
    Registration forward, backward;
    ASSERT_EQ(register_points(pairs, forward), Status::Ok);
    ASSERT_EQ(register_points(swapped(pairs), backward), Status::Ok);
    const RigidTransform I = compose(forward.X_BT, backward.X_BT);
    SCOPED_TRACE(str(forward.X_BT) + " / " + str(backward.X_BT));
    EXPECT_LT(rot(rotation_error(I.R, Matrix3d::Identity())), 1e-13);
    EXPECT_LT(pos(I.t.norm()), 1e-13);
    EXPECT_LT(rms(std::abs(backward.rms_residual - forward.rms_residual)), 7e-15);
    EXPECT_EQ(backward.max_residual_index, forward.max_residual_index);
  }
}

TEST(Registration, ChangingTheTrackerFrameChangesTheTransformAccordingly) {
  // Measuring in another frame T' = Y·T (p_T' = Y·p_T) must give X_BT' = X_BT·Y⁻¹.
  std::mt19937_64 rng(kSeed + 1107);
  Worst rot("change of tracker frame: rotation difference [rad]"),
      pos("change of tracker frame: translation difference [m]"), rms("rms residual difference [m]");
  for (int c = 0; c < stress(500); ++c) {
    std::vector<PointPair> pairs = pairs_for(random_transform(rng), random_points_B(rng, 10), 1e-4, rng);
    Registration r, moved;
    ASSERT_EQ(register_points(pairs, r), Status::Ok);
    const RigidTransform Y = random_transform(rng);
    for (PointPair& p : pairs) p.p_T = apply(Y, p.p_T);
    ASSERT_EQ(register_points(pairs, moved), Status::Ok);
    const RigidTransform expected = compose(r.X_BT, inverse(Y));
    EXPECT_LT(rot(rotation_error(moved.X_BT.R, expected.R)), 3e-14) << str(Y);
    EXPECT_LT(pos((moved.X_BT.t - expected.t).norm()), 4e-13) << str(Y);
    EXPECT_LT(rms(std::abs(moved.rms_residual - r.rms_residual)), 1e-14);
  }
}

TEST(Registration, TransformHelpersComposeAndInvert) {
  std::mt19937_64 rng(kSeed + 1108);
  Worst assoc("|(A·B)·p − A·(B·p)| [m]"), round("|A⁻¹·(A·p) − p| [m]"), R_err("|A·A⁻¹ − I| rotation part"),
      t_err("|A·A⁻¹ − I| translation part [m]");
  for (int c = 0; c < 1000; ++c) {
    const RigidTransform A = random_transform(rng), B = random_transform(rng);
    const Vector3d p(uniform(rng, -2, 2), uniform(rng, -2, 2), uniform(rng, -2, 2));
    EXPECT_LT(assoc((apply(compose(A, B), p) - apply(A, apply(B, p))).norm()), 4e-14);
    EXPECT_LT(round((apply(inverse(A), apply(A, p)) - p).norm()), 4e-14);
    const RigidTransform I = compose(A, inverse(A));
    EXPECT_LT(R_err((I.R - Matrix3d::Identity()).cwiseAbs().maxCoeff()), 2e-14);
    EXPECT_LT(t_err(I.t.norm()), 1.5e-13);
  }
}

TEST(Registration, LargestResidualNamesTheOutlier) {
  std::mt19937_64 rng(kSeed + 1109);
  for (int k = 0; k < 15; ++k) {
    std::vector<PointPair> pairs = pairs_for(random_transform(rng), random_points_B(rng, 15), 10e-6, rng);
    pairs[static_cast<std::size_t>(k)].p_B.z() += 1e-3;
    Registration r;
    ASSERT_EQ(register_points(pairs, r), Status::Ok);
    EXPECT_EQ(r.max_residual_index, k);
    // A 1 mm outlier among 15 points: the fit spreads part of it, the rest stays on the point.
    EXPECT_GT(r.max_residual, 0.5e-3);
    EXPECT_LT(r.max_residual, 1e-3);
    EXPECT_EQ(r.max_residual,
              (apply(r.X_BT, pairs[static_cast<std::size_t>(k)].p_T) - pairs[static_cast<std::size_t>(k)].p_B).norm());
  }
}

TEST(Registration, ConditionIsTheRatioOfTheRotationHessiansEigenvalues) {
  // Points ±a x, ±b y, ±c z (a ≥ b ≥ c) in a random tracker frame: h = (a², b², c²)/3 and the
  // condition is (a² + b²)/(b² + c²) exactly (theory §11).
  std::mt19937_64 rng(kSeed + 1110);
  Worst cond("relative condition error"), sv("singular value error [m²]");
  for (int c = 0; c < 200; ++c) {
    const double a = uniform(rng, 0.5, 1.0), b = uniform(rng, 0.05, a), cz = uniform(rng, 0.0, b);
    std::vector<Vector3d> points;
    const Vector3d centre(uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5), uniform(rng, 1.0, 2.0));
    for (const double s : {-1.0, 1.0}) {
      points.push_back(centre + s * a * Vector3d::UnitX());
      points.push_back(centre + s * b * Vector3d::UnitY());
      points.push_back(centre + s * cz * Vector3d::UnitZ());
    }
    Registration r;
    ASSERT_EQ(register_points(pairs_for(random_transform(rng), points, 0.0, rng), r), Status::Ok);
    EXPECT_LT(cond(std::abs(r.condition / ((a * a + b * b) / (b * b + cz * cz)) - 1.0)), 8e-14)
        << a << " " << b << " " << cz;
    EXPECT_LT(sv((r.singular_values - Vector3d(a * a, b * b, cz * cz) / 3.0).norm()), 3e-15)
        << a << " " << b << " " << cz;
  }
}

// A line of points from 0.5 m to 1.5 m along u, with a lateral offset `lateral` [m] on every
// third point (along a direction perpendicular to u).
std::vector<Vector3d> line_points(std::mt19937_64& rng, int n, double lateral) {
  const Vector3d u = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized();
  const Vector3d v = u.unitOrthogonal();
  std::vector<Vector3d> points;
  for (int k = 0; k < n; ++k) {
    points.push_back(Vector3d(0.1, -0.2, 1.2) + uniform(rng, 0.5, 1.5) * u + (k % 3 == 0 ? lateral : 0.0) * v);
  }
  return points;
}

TEST(Registration, TooFewOrNonFinitePointsAreReported) {
  std::mt19937_64 rng(kSeed + 1111);
  const std::vector<PointPair> pairs = pairs_for(random_transform(rng), random_points_B(rng, 6), 0.0, rng);
  Registration r;
  for (std::size_t n = 0; n < 3; ++n) {
    EXPECT_EQ(register_points(std::span<const PointPair>(pairs.data(), n), r), Status::TooFewPoints) << n;
    EXPECT_EQ(r.count, static_cast<int>(n));
    EXPECT_TRUE(std::isnan(r.rms_residual));
  }
  for (std::size_t k = 0; k < 6; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      for (const double bad : {kNan, kInf, -kInf}) {
        std::vector<PointPair> broken = pairs;
        (k % 2 == 0 ? broken[k].p_T : broken[k].p_B)[axis] = bad;
        EXPECT_EQ(register_points(broken, r), Status::NonFiniteInput) << "pair " << k << " axis " << axis << " " << bad;
        EXPECT_EQ(r.X_BT.R, Matrix3d::Identity());
      }
    }
  }
  // Finite coordinates whose squares overflow.
  std::vector<PointPair> huge = pairs;
  huge[1].p_T.x() = 1e300;
  EXPECT_EQ(register_points(huge, r), Status::NonFiniteInput);
}

TEST(Registration, CoincidentAndCollinearPointsAreReportedNotSolved) {
  std::mt19937_64 rng(kSeed + 1112);
  const RigidTransform X = random_transform(rng);
  Registration r;
  // All at one point, far from the origin, with and without tracker noise.
  for (const double sigma : {0.0, 10e-6}) {
    const std::vector<Vector3d> same(8, Vector3d(0.3, -0.2, 1.7));
    EXPECT_EQ(register_points(pairs_for(X, same, sigma, rng), r), Status::DegenerateRegistration) << sigma;
    EXPECT_EQ(register_points(swapped(pairs_for(X, same, sigma, rng)), r), Status::DegenerateRegistration) << sigma;
    EXPECT_EQ(r.X_BT.R, Matrix3d::Identity());
    EXPECT_TRUE(std::isnan(r.rms_residual));
  }
  const std::vector<PointPair> at_origin(5);
  EXPECT_EQ(register_points(at_origin, r), Status::DegenerateRegistration);
  // Coincident to within 1e-12 m at 2 m from the origin (5e-13 of the coordinates): the spread
  // is a few hundred roundings, isotropic, so the condition alone would let it through.
  for (int c = 0; c < 50; ++c) {
    std::vector<Vector3d> blur;
    for (int k = 0; k < 8; ++k) {
      blur.push_back(Vector3d(0.3, -0.2, 1.7) + 1e-12 * Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)));
    }
    EXPECT_EQ(register_points(pairs_for(X, blur, 0.0, rng), r), Status::DegenerateRegistration)
        << "condition " << r.condition;
    EXPECT_LT(r.condition, 1e4);
  }
  for (int c = 0; c < 200; ++c) {
    // Exactly collinear base points; the tracker sees them with or without noise.
    const double sigma = c % 2 == 0 ? 0.0 : 10e-6;
    const std::vector<PointPair> pairs = pairs_for(X, line_points(rng, 3 + c % 20, 0.0), sigma, rng);
    EXPECT_EQ(register_points(pairs, r), Status::DegenerateRegistration) << "sigma " << sigma;
    EXPECT_GT(r.condition, 1e8);
    // Noise on both sides does not hide the line either (10 µm on a 1 m line).
    std::vector<PointPair> both = pairs;
    for (PointPair& p : both) p.p_B += 10e-6 * Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
    EXPECT_EQ(register_points(both, r), Status::DegenerateRegistration) << "condition " << r.condition;
    EXPECT_EQ(register_points(swapped(both), r), Status::DegenerateRegistration) << "condition " << r.condition;
  }
  // Nearly collinear: 1 mm off a 1 m line is rejected, 5 cm off it is accepted.
  EXPECT_EQ(register_points(pairs_for(X, line_points(rng, 12, 1e-3), 0.0, rng), r), Status::DegenerateRegistration);
  EXPECT_EQ(register_points(pairs_for(X, line_points(rng, 12, 0.05), 0.0, rng), r), Status::Ok)
      << "condition " << r.condition;
}

TEST(Registration, TheConditionThresholdIsTheOption) {
  // ±1 m along x, ±b along y: condition (1 + b²)/b², the default limit 1e4 falls at b = 0.0100005.
  std::mt19937_64 rng(kSeed + 1113);
  const auto cross = [](double b) {
    return std::vector<Vector3d>{Vector3d(1, 0, 1.5), Vector3d(-1, 0, 1.5), Vector3d(0, b, 1.5), Vector3d(0, -b, 1.5)};
  };
  const RigidTransform X = random_transform(rng);
  Registration r;
  EXPECT_EQ(register_points(pairs_for(X, cross(0.0101), 0.0, rng), r), Status::Ok) << r.condition;
  EXPECT_EQ(register_points(pairs_for(X, cross(0.0099), 0.0, rng), r), Status::DegenerateRegistration) << r.condition;
  EXPECT_NEAR(r.condition, (1 + 0.0099 * 0.0099) / (0.0099 * 0.0099), 1e-6);
  RegistrationOptions lenient;
  lenient.max_condition = 1e5;
  EXPECT_EQ(register_points(pairs_for(X, cross(0.0099), 0.0, rng), r, lenient), Status::Ok);
  Worst rot("condition 1.02e4: rotation error [rad]");
  EXPECT_LT(rot(rotation_error(r.X_BT.R, X.R)), 1e-13);
}

TEST(Registration, NewStatusesAreNamedDescribedAndNotLimits) {
  for (const Status s : {Status::TooFewPoints, Status::DegenerateRegistration}) {
    EXPECT_FALSE(is_limit(s));
    EXPECT_NE(to_string(s), "unknown");
    EXPECT_NE(describe(s), "unknown status");
    EXPECT_EQ(describe(s).find(','), std::string_view::npos) << describe(s);  // stream answers are CSV
  }
  EXPECT_EQ(to_string(Status::TooFewPoints), "too_few_points");
  EXPECT_EQ(to_string(Status::DegenerateRegistration), "degenerate_registration");
}

}  // namespace
}  // namespace hexatwist::test
