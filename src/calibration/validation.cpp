// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/validation.hpp"

#include <algorithm>
#include <cmath>

#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {
namespace {

double axis_angle(const Vector3d& u, const Vector3d& v) noexcept {
  return std::atan2(u.normalized().cross(v.normalized()).norm(), u.normalized().dot(v.normalized()));
}

double compliance(double stiffness) noexcept { return std::isfinite(stiffness) ? 1.0 / stiffness : 0.0; }

double median(const std::vector<double>& sorted) noexcept { return sorted[sorted.size() / 2]; }

}  // namespace

PlatformDifference compare_platforms(const Model& a, const Model& b) noexcept {
  PlatformDifference d;
  for (int i = 0; i < kLegs; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const LegSpec &la = a.spec().legs[k], &lb = b.spec().legs[k];
    LegDifference& l = d.legs[k];
    l.base = lb.base_B - la.base_B;
    l.platform = lb.platform_P - la.platform_P;
    l.base_axis = axis_angle(la.axis_base_B, lb.axis_base_B);
    l.platform_axis = axis_angle(la.axis_platform_P, lb.axis_platform_P);
    l.lead = b.leg(i).lead - a.leg(i).lead;
    l.drive_lead = b.leg(i).lead / b.leg(i).drive_scale - a.leg(i).lead / a.leg(i).drive_scale;
    l.length_offset = b.geometry().length_offset[i] - a.geometry().length_offset[i];
    l.home_command = b.home_command()[i] - a.home_command()[i];
    l.compliance = compliance(lb.stiffness) - compliance(la.stiffness);
    l.play = lb.play - la.play;
    l.thread_differs = la.thread != lb.thread;
    for (const bool platform : {false, true}) {
      const double n = (platform ? l.platform : l.base).norm();
      if (n > d.largest_joint) {
        d.largest_joint = n;
        d.largest_joint_leg = i;
        d.largest_on_platform = platform;
      }
    }
  }
  d.observation = b.spec().observation_P - a.spec().observation_P;
  d.home_height = b.spec().home_height - a.spec().home_height;
  return d;
}

Status command_accuracy(const Model& commanding, const Model& actual, std::span<const Vector6d> poses,
                        CommandAccuracy& out) {
  out = CommandAccuracy{};
  if (poses.size() < static_cast<std::size_t>(kMinAccuracyStations)) return Status::InvalidArgument;
  std::vector<PointPair> pairs;
  pairs.reserve(poses.size());
  FkResult fk;
  for (const Vector6d& q : poses) {
    const Pose pose = Pose::from_vector(q);
    Vector6d command;
    LimitReport limit;
    if (const Status s = motor_commands(commanding, pose, Strategy::Compensated, command, limit); s != Status::Ok)
      return s;
    if (const Status s = forward_kinematics(actual, command, LengthKind::Motor, placement_from_pose(pose), fk);
        s != Status::Ok)
      return s;
    const Vector3d target = platform_point_B(commanding, placement_from_pose(pose), commanding.spec().observation_P);
    const Vector3d reached = platform_point_B(actual, fk.placement, actual.spec().observation_P);
    pairs.push_back({target, reached});
    out.gauge.push_back((reached - target).norm());
  }
  Registration reg;
  if (const Status s = register_points(pairs, reg); s != Status::Ok) return s;
  out.alignment = reg.X_BT;
  for (const PointPair& p : pairs) out.aligned.push_back((apply(reg.X_BT, p.p_T) - p.p_B).norm());
  std::sort(out.gauge.begin(), out.gauge.end());
  std::sort(out.aligned.begin(), out.aligned.end());
  out.gauge_median = median(out.gauge);
  out.aligned_median = median(out.aligned);
  out.gauge_max = out.gauge.back();
  out.aligned_max = out.aligned.back();
  return Status::Ok;
}

}  // namespace hexatwist
