// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/tolerance.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

#include "design/parallel.hpp"
#include "design/sampling.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist {

namespace {

// Two unit normals of an axis: e1 = unit(a x z) (unit(a x x) for a vertical axis), e2 = a x e1.
std::pair<Vector3d, Vector3d> axis_normals(const Vector3d& axis) {
  const Vector3d a = axis.normalized();
  Vector3d e1 = a.cross(Vector3d::UnitZ());
  if (e1.norm() < 1e-9) e1 = a.cross(Vector3d::UnitX());
  e1.normalize();
  return {e1, a.cross(e1)};
}

// `axis` turned by w1 about e1 and w2 about e2 (one rotation by w1 e1 + w2 e2), its length kept.
Vector3d tilted(const Vector3d& axis, double w1, double w2) {
  if (axis == Vector3d::Zero() || (w1 == 0.0 && w2 == 0.0)) return axis;
  const auto [e1, e2] = axis_normals(axis);
  const Vector3d w = w1 * e1 + w2 * e2;
  return Eigen::AngleAxisd(w.norm(), w.normalized()) * axis;
}

// The rotation angle of R [rad].
double rotation_angle(const Matrix3d& R) {
  const Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
}

// d(point A) = P dx for the platform perturbation dx = (dt, dw): [I, -[arm]x].
Eigen::Matrix<double, 3, 6> point_map(const Model& model, const Matrix3d& R_BP) {
  const Vector3d arm = R_BP * (model.spec().observation_P - model.spec().pivot_P);
  Eigen::Matrix<double, 3, 6> P;
  P.leftCols<3>() = Matrix3d::Identity();
  P.rightCols<3>() << 0, arm.z(), -arm.y(), -arm.z(), 0, arm.x(), arm.y(), -arm.x(), 0;
  return P;
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n) : x(static_cast<std::size_t>(n)), w(static_cast<std::size_t>(n)) {
    for (int i = 0; i < n; ++i) {
      double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x[static_cast<std::size_t>(i)] = z;
      w[static_cast<std::size_t>(i)] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

const GaussLegendre& outer_rule() {
  static const GaussLegendre rule(24);
  return rule;
}
constexpr int kInnerPoints = 16;  // midpoints on [0, pi/2] of a smooth periodic integrand

// Order statistic quantile (linear interpolation between the sorted values, "type 7").
ErrorQuantiles sample_quantiles(std::vector<double> v) {
  ErrorQuantiles q;
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return q;
  std::sort(v.begin(), v.end());
  const auto at = [&](double p) {
    const double h = p * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  q.median = at(0.5);
  q.p95 = at(0.95);
  q.max = v.back();
  return q;
}

}  // namespace

PlatformErrors error_sigmas(const Model& nominal, const ToleranceSigmas& s) {
  PlatformErrors sd;
  for (int i = 0; i < kLegs; ++i) {
    const bool lead = nominal.leg(i).lead > 0.0;
    sd.segment<kLegErrors>(kLegErrors * i) << s.base_joint, s.base_joint, s.base_joint, s.platform_joint,
        s.platform_joint, s.platform_joint, s.base_axis, s.base_axis, s.platform_axis, s.platform_axis,
        lead ? s.lead : 0.0, s.offset;
  }
  return sd;
}

PlatformErrors sample_errors(const Model& nominal, const ToleranceSigmas& sigmas, std::uint64_t seed,
                             std::uint64_t index) {
  const PlatformErrors sd = error_sigmas(nominal, sigmas);
  detail::SampleStream r(seed, index);
  PlatformErrors e;
  for (int j = 0; j < kPlatformErrors; ++j) e[j] = sd[j] * r.normal();
  return e;
}

ModelSpec real_platform(const Model& nominal, const PlatformErrors& e) {
  ModelSpec spec = nominal.spec();
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    const auto d = e.segment<kLegErrors>(kLegErrors * i);
    leg.base_B += d.segment<3>(0);
    leg.platform_P += d.segment<3>(3);
    leg.axis_base_B = tilted(leg.axis_base_B, d[6], d[7]);
    leg.axis_platform_P = tilted(leg.axis_platform_P, d[8], d[9]);
    if (leg.lead > 0.0) {
      // The drive keeps converting with its (nominal) lead; the nut travels by the real one.
      if (std::isnan(leg.drive_lead)) leg.drive_lead = leg.lead;
      leg.lead *= 1.0 + d[10];
    }
    leg.length_offset += d[11];
    leg.home_command = nominal.home_command()[i];
  }
  return spec;
}

CalibrationStep perfect_calibration_step() {
  return [](const Model&, const Model& real, std::uint64_t, CalibratedController& controller) {
    controller.spec = real.spec();
    return Status::Ok;
  };
}

// ---------------------------------------------------------------------------------------------

void ErrorHistogram::add(double value) noexcept {
  int bin;
  if (!(value >= kLowest)) {
    bin = 0;  // below the lowest bin (zero included)
  } else {
    const double b = std::floor(std::log10(value / kLowest) * kPerDecade);
    bin = b >= kPerDecade * kDecades ? kBins - 1 : 1 + static_cast<int>(b);
  }
  ++counts[static_cast<std::size_t>(bin)];
}

void ErrorHistogram::merge(const ErrorHistogram& other) noexcept {
  for (std::size_t k = 0; k < counts.size(); ++k) counts[k] += other.counts[k];
}

std::uint64_t ErrorHistogram::total() const noexcept {
  std::uint64_t t = 0;
  for (const std::uint64_t c : counts) t += c;
  return t;
}

double ErrorHistogram::quantile(double q) const noexcept {
  const std::uint64_t n = total();
  if (n == 0 || !(q > 0.0 && q < 1.0)) return NAN;
  const double target = q * static_cast<double>(n);
  double below = 0.0;
  for (int k = 0; k < kBins; ++k) {
    const double c = static_cast<double>(counts[static_cast<std::size_t>(k)]);
    if (below + c >= target && c > 0.0) {
      if (k == 0) return 0.0;
      if (k == kBins - 1) return kLowest * std::pow(10.0, kDecades);
      const double f = (target - below) / c;  // share of the bin's values below the quantile
      return kLowest * std::pow(10.0, (k - 1 + f) / kPerDecade);
    }
    below += c;
  }
  return NAN;
}

double ErrorHistogram::cdf(double value) const noexcept {
  const std::uint64_t n = total();
  if (n == 0) return NAN;
  if (!(value >= kLowest)) return static_cast<double>(counts[0]) / static_cast<double>(n);
  const double position = std::log10(value / kLowest) * kPerDecade;  // bins from the lowest bin's start
  if (position >= kPerDecade * kDecades) return 1.0;
  const auto bin = static_cast<int>(std::floor(position));
  double below = 0.0;
  for (int k = 0; k <= bin; ++k) below += static_cast<double>(counts[static_cast<std::size_t>(k)]);
  below += (position - bin) * static_cast<double>(counts[static_cast<std::size_t>(bin + 1)]);
  return below / static_cast<double>(n);
}

// ---------------------------------------------------------------------------------------------

void check_tolerance_sigmas(const ToleranceSigmas& s) {
  const auto check = [](double v, double most, const char* field, const char* unit) {
    if (!(v >= 0.0 && v <= most))
      throw ParameterError(fmt::format("tolerance: sigma of {}: expected 0 to {:g} {}, got {:g}", field, most, unit, v),
                           field);
  };
  check(s.base_joint, kMaxSigmaLength, "base_joint", "m");
  check(s.platform_joint, kMaxSigmaLength, "platform_joint", "m");
  check(s.base_axis, kMaxSigmaAxis, "base_axis", "rad");
  check(s.platform_axis, kMaxSigmaAxis, "platform_axis", "rad");
  check(s.lead, kMaxSigmaLead, "lead", "(relative)");
  check(s.offset, kMaxSigmaLength, "offset", "m");
}

Status tolerance_linear(const Model& nominal, const std::vector<Pose>& poses, const ToleranceSigmas& sigmas,
                        ToleranceLinear& out, int threads) {
  check_tolerance_sigmas(sigmas);
  out = ToleranceLinear{};
  const PlatformErrors sd = error_sigmas(nominal, sigmas);
  // Central differences on real_platform: the same construction as the Monte Carlo's platforms.
  // Steps where the residual is smooth and rounding (1e-16 of 2 m) is 1e-10 of the difference.
  std::vector<std::optional<Model>> plus(kPlatformErrors), minus(kPlatformErrors);
  std::vector<double> step(kPlatformErrors, 0.0);
  for (int j = 0; j < kPlatformErrors; ++j) {
    if (sd[j] == 0.0) continue;
    const int kind = j % kLegErrors;
    step[static_cast<std::size_t>(j)] = kind < 6 ? 1e-6 : kind < 10 ? 1e-6 : kind == 10 ? 1e-7 : 1e-6;
    PlatformErrors e = PlatformErrors::Zero();
    e[j] = step[static_cast<std::size_t>(j)];
    plus[static_cast<std::size_t>(j)].emplace(real_platform(nominal, e));
    e[j] = -e[j];
    minus[static_cast<std::size_t>(j)].emplace(real_platform(nominal, e));
  }
  const std::size_t n = poses.size();
  out.point.resize(n);
  out.point_covariance.resize(n);
  out.position_covariance.resize(n);
  out.orientation_covariance.resize(n);
  std::vector<Status> status(n, Status::Ok);
  const Eigen::Matrix<double, kPlatformErrors, 1> variance = sd.cwiseProduct(sd);
  detail::for_blocks(n, 64, threads, [&](std::size_t begin, std::size_t end) {
    LegState legs;
    Vector6d f_plus, f_minus;
    for (std::size_t k = begin; k < end; ++k) {
      Vector6d m;
      LimitReport report;
      Status s = motor_commands(nominal, poses[k], Strategy::Compensated, m, report);
      const Placement x = placement_from_pose(poses[k]);
      Matrix6d J;
      if (s == Status::Ok) s = inverse_kinematics(nominal, x, legs);
      if (s == Status::Ok) s = length_jacobian(nominal, legs, LengthKind::Motor, J);
      Eigen::Matrix<double, 6, kPlatformErrors> B = Eigen::Matrix<double, 6, kPlatformErrors>::Zero();
      for (int j = 0; j < kPlatformErrors && s == Status::Ok; ++j) {
        if (step[static_cast<std::size_t>(j)] == 0.0) continue;
        s = fk_residual(*plus[static_cast<std::size_t>(j)], x, m, LengthKind::Motor, legs, f_plus, nullptr);
        if (s == Status::Ok)
          s = fk_residual(*minus[static_cast<std::size_t>(j)], x, m, LengthKind::Motor, legs, f_minus, nullptr);
        B.col(j) = (f_plus - f_minus) / (2.0 * step[static_cast<std::size_t>(j)]);
      }
      if (s != Status::Ok) {
        status[k] = s;
        continue;
      }
      // The real pose solves f(x + dx, e) = 0: J dx + B e = 0 (implicit function theorem).
      const Eigen::Matrix<double, 6, kPlatformErrors> A = -J.partialPivLu().solve(B);
      out.point[k] = point_map(nominal, x.R_BP) * A;
      const auto cov = [&](const Eigen::Matrix<double, 3, kPlatformErrors>& M) -> Matrix3d {
        return M * variance.asDiagonal() * M.transpose();
      };
      out.point_covariance[k] = cov(out.point[k]);
      out.position_covariance[k] = cov(A.topRows<3>());
      out.orientation_covariance[k] = cov(A.bottomRows<3>());
    }
  });
  for (const Status s : status)
    if (s != Status::Ok) return s;
  return Status::Ok;
}

namespace {

// What every platform of a study shares: the poses and the nominal model's commands for them.
struct StudyPoses {
  const std::vector<Pose>& poses;
  std::vector<Vector6d> commands;
  std::vector<Placement> placements;
};

// The errors of one (platform, pose): point A, pivot position [m], orientation [rad].
struct PoseErrors {
  double point = 0.0, position = 0.0, orientation = 0.0;
};

// The errors of the real placement `y` (P in B) against the commanded `x` in a calibration's
// frames: y re-expressed as the controller's P in its B; point A the real one against where the
// controller's model puts it.
PoseErrors calibrated_errors(const Model& real, const Model& controller, const CalibratedController& c,
                             const Placement& y, const Placement& x) {
  const ModelSpec& spec = real.spec();
  Placement z;
  z.R_BP = c.X_CB.R * y.R_BP * c.X_PC.R;
  const Vector3d pivot_B = platform_point_B(real, y, apply(c.X_PC, spec.pivot_P));  // the controller's pivot
  z.t = apply(c.X_CB, pivot_B) - real.pivot_home_B();
  const Vector3d A_C = apply(c.X_CB, platform_point_B(real, y, spec.observation_P));
  PoseErrors e;
  e.point = (A_C - platform_point_B(controller, x, controller.spec().observation_P)).norm();
  e.position = (z.t - x.t).norm();
  e.orientation = rotation_angle(z.R_BP * x.R_BP.transpose());
  return e;
}

// The errors in the nominal frames, point A at the nominal arm.
PoseErrors nominal_frame_errors(const Vector3d& arm_P, const Placement& y, const Placement& x) {
  const Vector3d dt = y.t - x.t;
  PoseErrors e;
  e.position = dt.norm();
  e.orientation = rotation_angle(y.R_BP * x.R_BP.transpose());
  e.point = (dt + (y.R_BP - x.R_BP) * arm_P).norm();
  return e;
}

struct Histograms {
  ErrorHistogram point, position, orientation;
};

// Platform `index` with errors `e` (slot k of `out`): built, calibrated if asked. Without a
// controller `real` is left empty; the calibration's status goes to out.calibration.
void platform_setup(const Model& nominal, const ToleranceOptions& o, const PlatformErrors& e, std::uint64_t index,
                    std::size_t k, ToleranceChunk& out, std::optional<Model>& real, std::optional<Model>& controller,
                    CalibratedController& calibrated) {
  Status calibration = Status::Ok;
  try {
    real.emplace(real_platform(nominal, e));
    if (o.calibration) {
      calibrated.spec = nominal.spec();
      calibration = o.calibration(nominal, *real, index, calibrated);
      if (calibration == Status::Ok) controller.emplace(calibrated.spec);
    }
  } catch (const Error&) {
    // A platform the Model refuses (its home outside a limit), or a calibrated configuration.
    if (real && o.calibration && calibration == Status::Ok) calibration = Status::NonFiniteInput;
  }
  out.calibration[k] = static_cast<std::uint8_t>(calibration);
  if (o.calibration && !controller) real.reset();
}

// Platform `index` of a study into slot k of `out` and the histograms.
void study_platform(const Model& nominal, const StudyPoses& sp, const ToleranceOptions& o,
                    const ToleranceLinear* linear, std::uint64_t index, std::size_t k, ToleranceChunk& out,
                    Histograms& h) {
  const std::size_t np = sp.poses.size();
  const PlatformErrors e = sample_errors(nominal, o.sigmas, o.seed, index);
  std::optional<Model> real, controller;
  CalibratedController calibrated;
  platform_setup(nominal, o, e, index, k, out, real, controller, calibrated);
  if (!real) {
    out.failures[k] = static_cast<std::uint32_t>(np);
    out.max_point[k] = out.rms_point[k] = out.max_position[k] = out.max_orientation[k] = NAN;
    if (o.linear_worst) out.max_point_linear[k] = NAN;
    return;
  }
  Eigen::VectorXd z;  // the linear model's parameter errors after a calibration
  if (o.linear_worst && !linear->point_factor.empty()) linear->draw(index, z);
  const Vector3d arm_P = nominal.spec().observation_P - nominal.spec().pivot_P;
  double sum2 = 0.0;
  std::size_t counted = 0;
  FkResult fk;
  for (std::size_t p = 0; p < np; ++p) {
    Vector6d m = sp.commands[p];
    LimitReport report;
    if ((controller && motor_commands(*controller, sp.poses[p], Strategy::Compensated, m, report) != Status::Ok) ||
        forward_kinematics(*real, m, LengthKind::Motor, sp.placements[p], fk) != Status::Ok) {
      ++out.failures[k];
      continue;
    }
    const PoseErrors d = controller ? calibrated_errors(*real, *controller, calibrated, fk.placement, sp.placements[p])
                                    : nominal_frame_errors(arm_P, fk.placement, sp.placements[p]);
    out.max_point[k] = std::max(out.max_point[k], d.point);
    out.max_position[k] = std::max(out.max_position[k], d.position);
    out.max_orientation[k] = std::max(out.max_orientation[k], d.orientation);
    sum2 += d.point * d.point;
    ++counted;
    h.point.add(d.point);
    h.position.add(d.position);
    h.orientation.add(d.orientation);
    if (o.linear_worst)
      out.max_point_linear[k] = std::max(
          out.max_point_linear[k], z.size() > 0 ? (linear->point_factor[p] * z).norm() : (linear->point[p] * e).norm());
  }
  out.rms_point[k] = counted ? std::sqrt(sum2 / static_cast<double>(counted)) : NAN;
}

}  // namespace

Status tolerance_chunk(const Model& nominal, const std::vector<Pose>& poses, const ToleranceOptions& o,
                       std::uint64_t first, std::size_t count, ToleranceChunk& out, const ToleranceLinear* linear) {
  check_tolerance_sigmas(o.sigmas);
  out = ToleranceChunk{};
  out.first = first;
  const std::size_t np = poses.size();
  if (o.linear_worst &&
      (linear == nullptr || (linear->point.size() != np && (linear->point_factor.size() != np || !linear->draw))))
    return Status::NonFiniteInput;
  // The nominal commands, once for every platform that has no calibration of its own.
  StudyPoses sp{poses, std::vector<Vector6d>(np), std::vector<Placement>(np)};
  for (std::size_t k = 0; k < np; ++k) {
    LimitReport report;
    if (const Status s = motor_commands(nominal, poses[k], Strategy::Compensated, sp.commands[k], report);
        s != Status::Ok)
      return s;
    sp.placements[k] = placement_from_pose(poses[k]);
  }
  out.max_point.assign(count, 0.0);
  out.rms_point.assign(count, 0.0);
  out.max_position.assign(count, 0.0);
  out.max_orientation.assign(count, 0.0);
  out.max_point_linear.assign(count, o.linear_worst ? 0.0 : NAN);
  out.failures.assign(count, 0);
  out.calibration.assign(count, static_cast<std::uint8_t>(Status::Ok));
  std::mutex merge;
  detail::for_blocks(count, o.calibration ? 1 : 8, o.threads, [&](std::size_t begin, std::size_t end) {
    Histograms h;
    for (std::size_t k = begin; k < end; ++k) study_platform(nominal, sp, o, linear, first + k, k, out, h);
    // Integer counts: the sum does not depend on the order the blocks end in.
    const std::lock_guard<std::mutex> lock(merge);
    out.point.merge(h.point);
    out.position.merge(h.position);
    out.orientation.merge(h.orientation);
  });
  return Status::Ok;
}

void append_chunk(ToleranceChunk& into, const ToleranceChunk& next) {
  if (into.size() == 0 && into.point.total() == 0) into.first = next.first;
  const auto append = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  append(into.max_point, next.max_point);
  append(into.rms_point, next.rms_point);
  append(into.max_position, next.max_position);
  append(into.max_orientation, next.max_orientation);
  append(into.max_point_linear, next.max_point_linear);
  append(into.failures, next.failures);
  append(into.calibration, next.calibration);
  into.point.merge(next.point);
  into.position.merge(next.position);
  into.orientation.merge(next.orientation);
}

// ---------------------------------------------------------------------------------------------

namespace {

// The directions of the closed-form part: cos^2 and sin^2 of the midpoints on [0, pi/2].
struct InnerRule {
  std::array<double, kInnerPoints> c2, s2;
  InnerRule() {
    for (int j = 0; j < kInnerPoints; ++j) {
      const double psi = 0.5 * kPi * (j + 0.5) / kInnerPoints;
      c2[static_cast<std::size_t>(j)] = std::cos(psi) * std::cos(psi);
      s2[static_cast<std::size_t>(j)] = std::sin(psi) * std::sin(psi);
    }
  }
};
const InnerRule& inner_rule() {
  static const InnerRule rule;
  return rule;
}

// P(l0 z0^2 + l1 z1^2 + l2 z2^2 <= r^2) for standard normal z and 0 <= l0 <= l1 <= l2: z2 by
// Gauss-Legendre over the interval where the rest can hold what is left, the rest in closed form
// over directions: P(l0 z0^2 + l1 z1^2 <= s) = 1 - (2/pi) int_0^{pi/2} exp(-s / (2 (l0 cos^2 +
// l1 sin^2))) dpsi (polar coordinates of (z0, z1); docs/theory/design.md §18).
double chi_cdf(const Vector3d& l, double r) noexcept {
  if (!(r > 0.0)) return 0.0;
  if (!std::isfinite(r) || !(l[2] > 0.0)) return 1.0;
  const double c = std::min(r / std::sqrt(l[2]), 9.0);  // the normal density beyond 9 is 1e-18
  const GaussLegendre& g = outer_rule();
  const InnerRule& in = inner_rule();
  double sum = 0.0;
  for (std::size_t k = 0; k < g.x.size(); ++k) {
    const double z = c * g.x[k];
    const double s = r * r - l[2] * z * z;
    double inner;
    if (!(s > 0.0)) {
      inner = 0.0;
    } else if (!(l[1] > 0.0)) {
      inner = 1.0;  // l0 = l1 = 0
    } else {
      double e = 0.0;
      for (int j = 0; j < kInnerPoints; ++j)
        e += std::exp(-s /
                      (2.0 * (l[0] * in.c2[static_cast<std::size_t>(j)] + l[1] * in.s2[static_cast<std::size_t>(j)])));
      inner = 1.0 - e / kInnerPoints;
    }
    sum += g.w[k] * std::exp(-0.5 * z * z) * inner;
  }
  return std::clamp(sum * c / std::sqrt(2.0 * kPi), 0.0, 1.0);
}

Vector3d eigenvalues(const Matrix3d& C) {
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(C, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0);  // ascending
}

}  // namespace

double gaussian_norm_cdf(const Matrix3d& C, double r) noexcept { return chi_cdf(eigenvalues(C), r); }

double gaussian_norm_mixture_quantile(const std::vector<Matrix3d>& covariances, double q, int threads) {
  if (covariances.empty() || !(q > 0.0 && q < 1.0)) return NAN;
  std::vector<Vector3d> l(covariances.size());
  double hi = 0.0, lo = INFINITY;
  for (std::size_t k = 0; k < l.size(); ++k) {
    l[k] = eigenvalues(covariances[k]);
    hi = std::max(hi, std::sqrt(l[k].sum()));  // |z|^2 has mean trace C
    if (l[k][2] > 0.0) lo = std::min(lo, std::sqrt(l[k][2]));
  }
  if (!(hi > 0.0)) return 0.0;
  std::vector<double> part(l.size());
  const auto mixture = [&](double log_r) {
    const double r = std::exp(log_r);
    detail::for_blocks(l.size(), 256, threads, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) part[k] = chi_cdf(l[k], r);
    });
    double s = 0.0;
    for (const double p : part) s += p;  // in pose order: independent of the threads
    return s / static_cast<double>(l.size()) - q;
  };
  // A bracket in log r, then regula falsi with the Illinois modification, to 1e-9 of r.
  double a = std::log(lo * 1e-2), b = std::log(hi * 5.0);
  double fa = mixture(a), fb = mixture(b);
  for (int k = 0; k < 60 && fb < 0.0; ++k) b += 1.0, fb = mixture(b);
  for (int k = 0; k < 60 && fa > 0.0; ++k) a -= 1.0, fa = mixture(a);
  int side = 0;
  for (int it = 0; it < 200 && b - a > 1e-9; ++it) {
    const double x = (a * fb - b * fa) / (fb - fa);
    const double fx = mixture(x);
    if (fx == 0.0) return std::exp(x);
    if ((fx < 0.0) == (fa < 0.0)) {
      a = x, fa = fx;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = x, fb = fx;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return std::exp(0.5 * (a + b));
}

std::vector<double> gaussian_norm_mixture_cdf(const std::vector<Matrix3d>& covariances,
                                              const std::vector<double>& values, int threads) {
  std::vector<Vector3d> l(covariances.size());
  for (std::size_t k = 0; k < l.size(); ++k) l[k] = eigenvalues(covariances[k]);
  std::vector<double> out(values.size(), NAN);
  if (l.empty()) return out;
  std::vector<double> part(l.size());
  for (std::size_t v = 0; v < values.size(); ++v) {
    detail::for_blocks(l.size(), 256, threads, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) part[k] = chi_cdf(l[k], values[v]);
    });
    double s = 0.0;
    for (const double p : part) s += p;
    out[v] = s / static_cast<double>(l.size());
  }
  return out;
}

void linear_quantiles(const ToleranceLinear& linear, ToleranceSummary& s, int threads) {
  const auto quantiles = [&](const std::vector<Matrix3d>& cov) {
    ErrorQuantiles q;
    q.median = gaussian_norm_mixture_quantile(cov, 0.5, threads);
    q.p95 = gaussian_norm_mixture_quantile(cov, 0.95, threads);
    return q;
  };
  s.point_linear = quantiles(linear.point_covariance);
  s.position_linear = quantiles(linear.position_covariance);
  s.orientation_linear = quantiles(linear.orientation_covariance);
}

ToleranceSummary summarize_tolerance(const ToleranceChunk& c, std::size_t poses, const ToleranceLinear* linear,
                                     int threads) {
  ToleranceSummary s;
  s.platforms = c.size();
  s.poses = poses;
  for (const std::uint32_t f : c.failures) s.failures += f;
  for (const std::uint8_t status : c.calibration)
    ++s.calibration[std::min<std::size_t>(status, s.calibration.size() - 1)];
  const auto pooled = [](const ErrorHistogram& h, const std::vector<double>& worst) {
    ErrorQuantiles q;
    q.median = h.quantile(0.5);
    q.p95 = h.quantile(0.95);
    q.max = sample_quantiles(worst).max;
    return q;
  };
  s.point = pooled(c.point, c.max_point);
  s.position = pooled(c.position, c.max_position);
  s.orientation = pooled(c.orientation, c.max_orientation);
  s.worst_point = sample_quantiles(c.max_point);
  s.worst_point_linear = sample_quantiles(c.max_point_linear);
  s.worst_position = sample_quantiles(c.max_position);
  s.worst_orientation = sample_quantiles(c.max_orientation);
  if (linear != nullptr) linear_quantiles(*linear, s, threads);
  return s;
}

}  // namespace hexatwist
