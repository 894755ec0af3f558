// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/tolerance_calibration.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <array>
#include <charconv>
#include <cmath>
#include <functional>

#include "calibration/evaluator.hpp"
#include "calibration/solver.hpp"
#include "design/parallel.hpp"
#include "design/sampling.hpp"
#include "hexatwist/calibration/synthesis.hpp"
#include "hexatwist/error.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist {

namespace {

// The streams of a sample's tracker placement and noise: others than its manufacturing errors'.
constexpr std::uint64_t kTrackerStream = 0x3c6ef372fe94f82bULL;
constexpr std::uint64_t kNoiseStream = 0x510e527fade682d1ULL;

// The nominal model's compensated commands for each station of the plan, held there.
Status station_commands(const Model& nominal, const TrackerCalibration& c, std::vector<Vector6d>& out) {
  out.resize(c.stations.size());
  LimitReport limit;
  for (std::size_t k = 0; k < c.stations.size(); ++k)
    if (const Status s =
            motor_commands(nominal, Pose::from_vector(c.stations[k]), Strategy::Compensated, out[k], limit);
        s != Status::Ok)
      return s;
  return Status::Ok;
}

// The targets a calibration measures, in order: the observation point of `platform`, then the extra ones [m, P].
std::vector<Vector3d> targets_P(const Model& platform, const TrackerCalibration& c) {
  std::vector<Vector3d> out{platform.spec().observation_P};
  out.insert(out.end(), c.extra_targets_P.begin(), c.extra_targets_P.end());
  return out;
}

// The plan's observations of the nominal platform without noise, the tracker frame at B: the
// points of a station and target repeated, so that its group weighs as many points as the tracker
// records (the order of tracker_observations: station, target, point).
Status plan_observations(const Model& nominal, const TrackerCalibration& c, std::vector<Observation>& out) {
  out.clear();
  std::vector<Vector6d> commands;
  if (const Status s = station_commands(nominal, c, commands); s != Status::Ok) return s;
  const std::vector<Vector3d> targets = targets_P(nominal, c);
  for (std::size_t k = 0; k < c.stations.size(); ++k)
    for (std::size_t t = 0; t < targets.size(); ++t) {
      Observation o;
      o.motor = commands[k];
      o.target = static_cast<int>(t);
      o.p_T = platform_point_B(nominal, placement_from_pose(Pose::from_vector(c.stations[k])), targets[t]);
      out.insert(out.end(), static_cast<std::size_t>(c.points), o);
    }
  return Status::Ok;
}

// The nominal parameters of `set` with the extra targets where the calibration puts them.
Eigen::VectorXd plan_theta(const ParameterSet& set, const TrackerCalibration& c) {
  Eigen::VectorXd theta = set.nominal_vector();
  for (std::size_t t = 0; t < c.extra_targets_P.size(); ++t)
    theta.segment<3>(set.target_index() + 3 * static_cast<Eigen::Index>(t + 1)) = c.extra_targets_P[t];
  return theta;
}

// The identification's Jacobian (platform parameters, then the tracker frame) of the plan's groups
// at the nominal parameters: the rows identify's Evaluator gives, each weighted by sqrt(points).
Status plan_jacobian(const ParameterSet& set, const Eigen::VectorXd& theta, std::span<const Observation> observations,
                     const ObservationGroups& groups, const FkOptions& fk, Eigen::MatrixXd& J) {
  detail::Evaluator evaluator(set, observations, groups, fk);
  Eigen::VectorXd e;
  return evaluator.evaluate(theta, 1.0, RigidTransform{}, e, &J);
}

}  // namespace

IdentificationOptions study_identification_options() {
  IdentificationOptions o;
  o.model = CalibrationModel::Geometry;
  o.leads = LeadFit::PerLeg;
  o.folds = 0;
  o.accuracy_poses = 0;
  return o;
}

void check_tracker_calibration(const TrackerCalibration& c) {
  if (c.stations.empty()) throw ParameterError("calibration: the station plan has no station", "station_plan");
  for (std::size_t s = 0; s < c.stations.size(); ++s)
    if (!c.stations[s].allFinite())
      throw ParameterError(fmt::format("calibration: station {} holds NaN or inf", s + 1), "station_plan");
  if (!(c.noise > 0.0 && c.noise < kMaxTrackerNoise))
    throw ParameterError(fmt::format("calibration: the tracker's noise must be > 0 and below {:g} m, got {:g}",
                                     kMaxTrackerNoise, c.noise),
                         "tracker_noise");
  if (c.points < 1 || c.points > kMaxPointsPerStation)
    throw ParameterError(
        fmt::format("calibration: expected 1 to {} points per station, got {}", kMaxPointsPerStation, c.points),
        "points_per_station");
  check_identification_options(c.identification);
  if (c.identification.model != CalibrationModel::Geometry)
    throw ParameterError("calibration: the identification must fit the geometry model (the joints the study moves)",
                         "identification");
  if (c.points == 1 && std::isnan(c.identification.tracker_noise))
    throw ParameterError(
        "calibration: one point per station has no scatter to measure the tracker's noise by; record two or more, or "
        "give identification.tracker_noise",
        "points_per_station");
  if (c.extra_targets_P.size() + 1 > kMaxTargets)
    throw ParameterError(fmt::format("calibration: {} targets with the observation point, at most {}",
                                     c.extra_targets_P.size() + 1, kMaxTargets),
                         "targets");
  for (std::size_t t = 0; t < c.extra_targets_P.size(); ++t) {
    const Vector3d& p = c.extra_targets_P[t];
    if (!(p.allFinite() && p.norm() <= 10.0))
      throw ParameterError(
          fmt::format("calibration: target {} must be finite and within 10 m of the platform frame's origin", t + 2),
          "targets");
  }
}

namespace {

// The targets apart: ParameterError when two (the observation point among them) are within 1 mm.
void check_targets_apart(const Model& nominal, const TrackerCalibration& c) {
  const std::vector<Vector3d> targets = targets_P(nominal, c);
  for (std::size_t a = 0; a < targets.size(); ++a)
    for (std::size_t b = a + 1; b < targets.size(); ++b)
      if ((targets[a] - targets[b]).norm() < 1e-3)
        throw ParameterError(fmt::format("calibration: targets {} and {} are within 1 mm of each other (target 1 is "
                                         "the observation point): one point cannot be measured twice",
                                         a + 1, b + 1),
                             "targets");
}

}  // namespace

std::vector<Vector6d> random_station_plan(const Model& nominal, const StationsSpec& spec) {
  std::vector<Vector6d> plan{Vector6d::Zero()};
  const std::vector<Vector6d> stations = random_stations(nominal, Strategy::Compensated, spec);
  plan.insert(plan.end(), stations.begin(), stations.end());
  plan.push_back(Vector6d::Zero());
  return plan;
}

std::vector<Vector6d> run_stations(const TimedPoses& run) {
  std::vector<Vector6d> stations;
  bool held = false;
  for (std::size_t k = 1; k < run.poses.size(); ++k) {
    const Vector6d q = run.poses[k].to_vector();
    const bool same = q == run.poses[k - 1].to_vector();
    if (same && !held) stations.push_back(q);
    held = same;
  }
  return stations;
}

RigidTransform sample_tracker_frame(const TrackerCalibration& c, std::uint64_t index) {
  detail::SampleStream random(c.seed ^ kTrackerStream, index);
  return random_tracker_frame(random.bits());
}

Status joint_frames(const Model& nominal, const Model& real, RigidTransform& X_BJ, RigidTransform& X_PJ) {
  std::array<PointPair, kLegs> base, platform;
  for (std::size_t i = 0; i < kLegs; ++i) {
    const LegSpec& n = nominal.spec().legs[i];
    const LegSpec& r = real.spec().legs[i];
    base[i] = {n.base_B, r.base_B};
    platform[i] = {n.platform_P, r.platform_P};
  }
  Registration b, p;
  if (const Status s = register_points(base, b); s != Status::Ok) return s;
  if (const Status s = register_points(platform, p); s != Status::Ok) return s;
  X_BJ = b.X_BT;
  X_PJ = p.X_BT;
  return Status::Ok;
}

std::vector<Vector3d> tracker_noise(const TrackerCalibration& c, std::uint64_t index) {
  detail::SampleStream random(c.seed ^ kNoiseStream, index);
  std::vector<Vector3d> noise(c.stations.size() * (1 + c.extra_targets_P.size()) *
                              static_cast<std::size_t>(std::max(c.points, 0)));
  for (Vector3d& n : noise)
    for (int a = 0; a < 3; ++a) n[a] = c.noise * random.normal();
  return noise;
}

Status tracker_observations(const Model& nominal, const Model& real, const TrackerCalibration& c, std::uint64_t index,
                            std::vector<Observation>& out) {
  out.clear();
  const RigidTransform X_TB = inverse(sample_tracker_frame(c, index));
  const std::vector<Vector3d> noise = tracker_noise(c, index);
  out.reserve(noise.size());
  auto next = noise.begin();
  std::vector<Vector6d> commands;
  if (const Status s = station_commands(nominal, c, commands); s != Status::Ok) return s;
  const std::vector<Vector3d> targets = targets_P(real, c);
  FkResult fk;
  for (std::size_t station = 0; station < c.stations.size(); ++station) {
    Observation o;
    o.motor = commands[station];
    // Where the held commands put the real platform, and its targets there.
    const Placement guess = placement_from_pose(Pose::from_vector(c.stations[station]));
    if (const Status s = forward_kinematics(real, o.motor, LengthKind::Motor, guess, fk); s != Status::Ok) return s;
    for (std::size_t t = 0; t < targets.size(); ++t) {
      o.target = static_cast<int>(t);
      const Vector3d p_T = apply(X_TB, platform_point_B(real, fk.placement, targets[t]));
      for (int k = 0; k < c.points; ++k) {
        o.p_T = p_T + *next++;
        out.push_back(o);
      }
    }
  }
  return Status::Ok;
}

Status calibrate_sample(const Model& nominal, const Model& real, const TrackerCalibration& c, std::uint64_t index,
                        Identification& out) {
  std::vector<Observation> observations;
  if (const Status s = tracker_observations(nominal, real, c, index, observations); s != Status::Ok) {
    out = Identification{};
    out.status = s;
    out.reason = fmt::format("the tracker's points: {}", describe(s));
    return s;
  }
  return identify(nominal, observations, out, c.identification);
}

CalibrationStep tracker_calibration_step(const TrackerCalibration& calibration) {
  check_tracker_calibration(calibration);
  return [c = calibration](const Model& nominal, const Model& real, std::uint64_t index, CalibratedController& out) {
    Identification id;
    if (const Status s = calibrate_sample(nominal, real, c, index, id); s != Status::Ok) return s;
    RigidTransform X_BJ;
    if (const Status s = joint_frames(nominal, real, X_BJ, out.X_PC); s != Status::Ok) return s;
    out.spec = id.corrected;
    // The real base in the identification's: through the tracker (its real placement, then the
    // identified one), or the real base joints' own frame.
    out.X_CB = c.frames == CalibratedFrames::Tracker ? compose(id.X_BT, inverse(sample_tracker_frame(c, index)))
                                                     : inverse(X_BJ);
    return Status::Ok;
  };
}

// ---------------------------------------------------------------------------------------------
// The linearised answer (theory design §18): the calibration's response to the tracker's noise and
// to the manufacturing errors it does not identify (the U-joint axes it leaves), at the nominal.

namespace {

// The calibration's linear model at the nominal: every axis in `every`, the identified parameters
// its columns `fitted`, the axes the identification leaves its columns `left`.
struct PlanModel {
  ParameterSet every;
  std::vector<Eigen::Index> fitted, left;
  std::vector<int> left_axes;  // the axis (0..11) of each pair of left columns
  Eigen::VectorXd left_sd;     // the left axes' manufacturing standard deviations [rad]
  Eigen::MatrixXd J_all;       // the plan's weighted Jacobian in every's columns
  ObservationGroups groups;
  double noise = 0.0;  // the tracker's noise the covariance assumes [m]
};

// The axes identify's AxisFit would fit with this plan: those whose two angles the plan determines
// to axis_sd_max at the tracker's noise, with every axis in the fit (AxisFit::Auto), all, or none.
AxisSelection chosen_axes(const TrackerCalibration& c, const PlanModel& m) {
  const IdentificationOptions& o = c.identification;
  AxisSelection chosen{};
  if (o.axes == AxisFit::None) return chosen;
  const detail::Conditioning cond = detail::conditioning(m.every, m.J_all, 1e300);
  for (int a = 0, k = m.every.axis_index(); a < 2 * kLegs; ++a) {
    if (!m.every.axes()[static_cast<std::size_t>(a)]) continue;
    // No covariance (the plan leaves some combination undetermined): no axis is determined.
    const double sd = cond.inverse_normal.size() == 0
                          ? std::numeric_limits<double>::infinity()
                          : m.noise * std::sqrt(std::max(cond.inverse_normal(k, k), cond.inverse_normal(k + 1, k + 1)));
    chosen[static_cast<std::size_t>(a)] = o.axes == AxisFit::All || sd <= o.axis_sd_max;
    k += 2;
  }
  return chosen;
}

// The plan's model: its Jacobian with every axis, the axes identify fits, the columns.
Status plan_model(const Model& nominal, const ToleranceSigmas& sigmas, const TrackerCalibration& c, PlanModel& m,
                  CalibratedLinear& lin) {
  const IdentificationOptions& o = c.identification;
  check_targets_apart(nominal, c);
  std::vector<Observation> observations;
  if (const Status s = plan_observations(nominal, c, observations); s != Status::Ok) return s;
  m.groups = group_observations(observations);
  m.noise = std::max(c.noise, o.tracker_noise_floor);
  AxisSelection all;
  all.fill(true);
  const int targets = 1 + static_cast<int>(c.extra_targets_P.size());
  m.every = ParameterSet(nominal, CalibrationModel::Geometry, o.lead_effect, all, targets, o.leads);
  if (const Status s = plan_jacobian(m.every, plan_theta(m.every, c), observations, m.groups, o.fk, m.J_all);
      s != Status::Ok)
    return s;
  const AxisSelection chosen = chosen_axes(c, m);
  lin.parameters = ParameterSet(nominal, CalibrationModel::Geometry, o.lead_effect, chosen, targets, o.leads);
  std::vector<double> sd;
  for (Eigen::Index j = 0; j < m.every.axis_index(); ++j) m.fitted.push_back(j);
  for (int a = 0, j = m.every.axis_index(); a < 2 * kLegs; ++a) {
    if (!m.every.axes()[static_cast<std::size_t>(a)]) continue;  // a leg without axes
    const bool fit = chosen[static_cast<std::size_t>(a)];
    (fit ? m.fitted : m.left).insert((fit ? m.fitted : m.left).end(), {j, j + 1});
    if (!fit) {
      m.left_axes.push_back(a);
      sd.insert(sd.end(), 2, a < kLegs ? sigmas.base_axis : sigmas.platform_axis);
    }
    j += 2;
  }
  for (Eigen::Index j = m.every.target_index(); j < m.every.size(); ++j) m.fitted.push_back(j);
  m.left_sd = Eigen::Map<const Eigen::VectorXd>(sd.data(), static_cast<Eigen::Index>(sd.size()));
  return Status::Ok;
}

// A square root L of a covariance, C = L L^T (C positive semi-definite).
Eigen::MatrixXd covariance_factor(const Eigen::MatrixXd& C) {
  const Eigen::LLT<Eigen::MatrixXd> llt(C);
  if (llt.info() == Eigen::Success) return llt.matrixL();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

// How the errors of point A, the pivot and the orientation at a pose move with the parameters
// (platform, then tracker frame), the pose's commands held.
struct PoseRows {
  Eigen::Matrix<double, 3, Eigen::Dynamic> point, position, orientation;
};

// The rows at `pose`, in the sign of the identification's residuals e = X_BT p - A (theory §13):
// -d(where the commands put them)/d(platform parameters); in the Tracker frames also how the
// identified tracker frame maps the real points (in the Joints frames those columns are zero).
Status pose_rows(const Model& platform, const ParameterSet& set, const Eigen::VectorXd& theta, const Pose& pose,
                 CalibratedFrames frames, PoseRows& out) {
  Vector6d m;
  LimitReport limit;
  FkResult fk;
  Eigen::Matrix<double, 6, Eigen::Dynamic> dx;
  Status s = motor_commands(platform, pose, Strategy::Compensated, m, limit);
  if (s == Status::Ok) s = forward_kinematics(platform, m, LengthKind::Motor, placement_from_pose(pose), fk);
  if (s == Status::Ok) s = detail::pose_sensitivity(platform, set, fk, m, dx);
  if (s != Status::Ok) return s;
  const int p = set.platform_size(), n = set.size();
  for (auto* r : {&out.point, &out.position, &out.orientation}) r->setZero(3, n);
  out.point.leftCols(p) = -detail::point_sensitivity(set, fk, dx, theta, 0);
  out.position.leftCols(p) = -dx.topRows<3>();
  out.orientation.leftCols(p) = -dx.bottomRows<3>();
  if (frames == CalibratedFrames::Tracker) {
    const Vector3d A_B = detail::target_B(platform, fk.placement, set, theta, 0);
    const Vector3d pivot_B = platform.pivot_home_B() + fk.placement.t;
    out.point.middleCols<3>(set.rotation_index()) = -detail::skew(A_B);  // exp(dw) R p = R p + dw x R p
    out.point.middleCols<3>(set.translation_index()).setIdentity();
    out.position.middleCols<3>(set.rotation_index()) = -detail::skew(pivot_B);
    out.position.middleCols<3>(set.translation_index()).setIdentity();
    out.orientation.middleCols<3>(set.rotation_index()).setIdentity();
  }
  return Status::Ok;
}

// The linear model's coordinates z of a sample: its identified parameters' errors L z_n, the
// least-squares response to its tracker noise e, L z_n = -(J^T J)^-1 J^T e, so z_n = -L^T J^T e /
// sigma^2 (C = sigma^2 (J^T J)^-1 = L L^T; e per group the weighted sum of its points' noise in B);
// then its left axes' errors over their standard deviations.
std::function<void(std::uint64_t, Eigen::VectorXd&)> same_errors(const Model& nominal, const ToleranceOptions& study,
                                                                 const TrackerCalibration& c, const PlanModel& m,
                                                                 const Eigen::MatrixXd& L) {
  const Eigen::MatrixXd J = m.J_all(Eigen::all, m.fitted);
  const Eigen::MatrixXd M = -L.transpose() * J.transpose() / (m.noise * m.noise);
  std::vector<std::array<Vector3d, 2>> across;  // the two directions across each left axis
  for (const int a : m.left_axes) across.push_back(m.every.axis_directions(a));
  return [nominal, study, c, M, groups = m.groups, sd = m.left_sd, across, axes = m.left_axes](std::uint64_t index,
                                                                                               Eigen::VectorXd& z) {
    const std::vector<Vector3d> noise_T = tracker_noise(c, index);
    const Matrix3d R_BT = sample_tracker_frame(c, index).R;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(M.cols());
    for (std::size_t k = 0; k < noise_T.size(); ++k) {
      const auto g = static_cast<std::size_t>(groups.group_of[k]);
      e.segment<3>(3 * static_cast<Eigen::Index>(g)) += R_BT * noise_T[k] / std::sqrt(groups.count[g]);
    }
    z.resize(M.rows() + sd.size());
    z.head(M.rows()) = M * e;
    // The sample's axes as built, in the identification's two directions across each.
    const ModelSpec real = real_platform(nominal, sample_errors(nominal, study.sigmas, study.seed, index));
    for (std::size_t u = 0; u < axes.size(); ++u) {
      const int a = axes[u];
      const LegSpec& r = real.legs[static_cast<std::size_t>(a % kLegs)];
      const LegSpec& n = nominal.spec().legs[static_cast<std::size_t>(a % kLegs)];
      const Vector3d d = a < kLegs ? Vector3d(r.axis_base_B.normalized() - n.axis_base_B.normalized())
                                   : Vector3d(r.axis_platform_P.normalized() - n.axis_platform_P.normalized());
      for (int i = 0; i < 2; ++i) {
        const auto row = static_cast<Eigen::Index>(2 * u) + i;
        z[M.rows() + row] = sd[row] > 0.0 ? d.dot(across[u][static_cast<std::size_t>(i)]) / sd[row] : 0.0;
      }
    }
  };
}

}  // namespace

Status calibrated_linear(const Model& nominal, const std::vector<Pose>& poses, const ToleranceOptions& study,
                         const TrackerCalibration& c, ToleranceLinear& out, CalibratedLinear* detail_out) {
  check_tolerance_sigmas(study.sigmas);
  check_tracker_calibration(c);
  out = ToleranceLinear{};
  CalibratedLinear lin;
  PlanModel m;
  if (const Status s = plan_model(nominal, study.sigmas, c, m, lin); s != Status::Ok) return s;
  lin.jacobian = m.J_all(Eigen::all, m.fitted);
  const detail::Conditioning cond = detail::conditioning(lin.parameters, lin.jacobian, c.identification.max_condition);
  lin.condition = cond.condition;
  if (cond.undetermined > 0) return Status::NotIdentifiable;
  lin.covariance = m.noise * m.noise * cond.inverse_normal;
  const Eigen::MatrixXd L = covariance_factor(lin.covariance);
  // The identified parameters' response to the left axes: (J^T J)^-1 J^T J_u, scaled by their sd.
  const Eigen::MatrixXd K = lin.covariance * lin.jacobian.transpose() * m.J_all(Eigen::all, m.left) *
                            m.left_sd.asDiagonal() / (m.noise * m.noise);
  const Eigen::VectorXd theta = plan_theta(m.every, c);
  const Model platform(m.every.platform(theta, 1.0));
  const std::size_t n = poses.size();
  for (auto* v : {&out.point_covariance, &out.position_covariance, &out.orientation_covariance}) v->resize(n);
  out.point_factor.resize(n);
  lin.point_error.resize(n);
  const int p = lin.parameters.platform_size();
  std::vector<Status> status(n, Status::Ok);
  detail::for_blocks(n, 16, study.threads, [&](std::size_t begin, std::size_t end) {
    PoseRows rows;
    for (std::size_t k = begin; k < end; ++k) {
      if (const Status s = pose_rows(platform, m.every, theta, poses[k], c.frames, rows); s != Status::Ok) {
        status[k] = s;
        continue;
      }
      // The pose's errors: J L z_n from the noise, (J K - J_u sd) z_u from the left axes.
      const auto factor = [&](const Eigen::Matrix<double, 3, Eigen::Dynamic>& R) {
        Eigen::Matrix<double, 3, Eigen::Dynamic> F(3, L.cols() + K.cols());
        const Eigen::Matrix<double, 3, Eigen::Dynamic> J = R(Eigen::all, m.fitted);
        F << J * L, J * K - R(Eigen::all, m.left) * m.left_sd.asDiagonal();
        return F;
      };
      out.point_factor[k] = factor(rows.point);
      out.point_covariance[k] = out.point_factor[k] * out.point_factor[k].transpose();
      const auto F_t = factor(rows.position), F_w = factor(rows.orientation);
      out.position_covariance[k] = F_t * F_t.transpose();
      out.orientation_covariance[k] = F_w * F_w.transpose();
      const auto G = rows.point(Eigen::all, m.fitted).leftCols(p);  // as predicted_errors
      lin.point_error[k] = std::sqrt(std::max(0.0, (G * lin.covariance.topLeftCorner(p, p) * G.transpose()).trace()));
    }
  });
  for (const Status s : status)
    if (s != Status::Ok) return s;
  out.draw = same_errors(nominal, study, c, m, L);
  if (detail_out != nullptr) *detail_out = std::move(lin);
  return Status::Ok;
}

// ---------------------------------------------------------------------------------------------

bool is_tracker_calibration(std::string_view name) noexcept { return name == "plan" || name.starts_with("stations:"); }

namespace {

// The plan a choice names; empty for none and perfect.
std::vector<Vector6d> chosen_plan(const Model& nominal, const CalibrationChoice& choice) {
  const std::string& name = choice.name;
  if (name == "none" || name == "perfect") return {};
  if (name == "plan") return choice.plan;
  if (name.starts_with("stations:")) {
    // stations:N[,SEED], whole numbers only (std::from_chars takes no sign, space or fraction).
    const std::string_view rest = std::string_view(name).substr(9);
    const std::size_t comma = rest.find(',');
    const std::string_view count = rest.substr(0, comma);
    const std::string_view seed = comma == std::string_view::npos ? std::string_view("1") : rest.substr(comma + 1);
    StationsSpec spec;
    const auto n = std::from_chars(count.data(), count.data() + count.size(), spec.count);
    const auto s = std::from_chars(seed.data(), seed.data() + seed.size(), spec.seed);
    if (n.ec == std::errc() && n.ptr == count.data() + count.size() && s.ec == std::errc() &&
        s.ptr == seed.data() + seed.size() && !seed.empty() && spec.count >= 1 && spec.count <= kMaxStations)
      return random_station_plan(nominal, spec);
    throw ParameterError(
        fmt::format("calibration: expected stations:N[,SEED] with N from 1 to {} and a whole seed, got '{}'",
                    kMaxStations, name),
        "calibration");
  }
  throw ParameterError(fmt::format("calibration: expected none, perfect, stations:N[,SEED] or plan, got '{}'", name),
                       "calibration");
}

}  // namespace

TrackerCalibration tracker_calibration_of(const Model& nominal, const CalibrationChoice& choice, std::uint64_t seed) {
  TrackerCalibration c;
  c.stations = chosen_plan(nominal, choice);
  if (c.stations.empty() && choice.name == "plan")
    throw ParameterError("calibration: plan needs a station plan (none given)", "station_plan");
  if (c.stations.empty() && !choice.extra_targets_P.empty())
    throw ParameterError(
        fmt::format("calibration: targets are measured by a tracker calibration, not by calibration {}", choice.name),
        "targets");
  c.noise = choice.tracker_noise;
  c.points = choice.points;
  c.seed = seed;
  c.frames = choice.frames;
  c.extra_targets_P = choice.extra_targets_P;
  if (c.points == 1) c.identification.tracker_noise = c.noise;  // no scatter to measure it by
  return c;
}

Status prepare_calibration(const Model& nominal, const std::vector<Pose>& poses, const CalibrationChoice& choice,
                           ToleranceOptions& options, ToleranceLinear& linear) {
  options.calibration = nullptr;
  const TrackerCalibration c = tracker_calibration_of(nominal, choice, options.seed);
  if (c.stations.empty()) {
    if (choice.name == "perfect") options.calibration = perfect_calibration_step();
    return tolerance_linear(nominal, poses, options.sigmas, linear, options.threads);
  }
  options.calibration = tracker_calibration_step(c);
  return calibrated_linear(nominal, poses, options, c, linear);
}

std::vector<Vector3d> target_layout(const Model& nominal, int extra) {
  const ModelSpec& spec = nominal.spec();
  const Vector3d a = spec.observation_P - spec.pivot_P;
  double radius = a.head<2>().norm();
  double angle = std::atan2(a.y(), a.x());
  if (radius < 0.1) {
    radius = 0.0;
    for (const LegSpec& leg : spec.legs) radius += (leg.platform_P - spec.pivot_P).head<2>().norm() / kLegs;
    angle = 0.0;
  }
  std::vector<Vector3d> out;
  for (int k = 1; k <= extra; ++k) {
    const double phi = angle + 2.0 * kPi * k / (extra + 1);
    out.emplace_back(spec.pivot_P.x() + radius * std::cos(phi), spec.pivot_P.y() + radius * std::sin(phi),
                     spec.observation_P.z());
  }
  return out;
}

std::vector<TargetLayout> target_layouts(const Model& nominal, const std::vector<Pose>& poses,
                                         const ToleranceOptions& study, const TrackerCalibration& calibration,
                                         int max_extra) {
  check_tolerance_sigmas(study.sigmas);
  if (max_extra < 0 || max_extra > kMaxLayoutTargets)
    throw ParameterError(
        fmt::format("target layouts: expected 0 to {} extra targets, got {}", kMaxLayoutTargets, max_extra),
        "target_layouts");
  std::vector<TargetLayout> out;
  for (int extra = 0; extra <= max_extra; ++extra) {
    TrackerCalibration c = calibration;
    c.extra_targets_P = target_layout(nominal, extra);
    TargetLayout& layout = out.emplace_back();
    layout.extra_targets_P = c.extra_targets_P;
    ToleranceLinear linear;
    layout.status = calibrated_linear(nominal, poses, study, c, linear);
    if (layout.status != Status::Ok) continue;
    ToleranceSummary summary;
    linear_quantiles(linear, summary, study.threads);
    layout.point = summary.point_linear;
    layout.position = summary.position_linear;
    layout.orientation = summary.orientation_linear;
  }
  return out;
}

}  // namespace hexatwist
