// SPDX-License-Identifier: BSD-3-Clause
// Batches of poses across the SIMD lanes (docs/theory/kinematics.md §8, "Batches"): one pose per
// lane, the six legs one after the other, where the real-time call (compensation.cpp) puts the
// legs across the lanes. The arithmetic is the real-time call's, expression for expression (the
// kernels of lanes.hpp with the leg's numbers in every lane and the rotation per lane), so that
// every pose's result is that call's bit for bit; a pose that fails a test goes through the
// single-pose path, which names the leg and limit.
#include "hexatwist/kinematics/batch.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>

#include "kinematics/compensation_internal.hpp"
#include "kinematics/lanes.hpp"

namespace hexatwist {
namespace {

using namespace detail;

/// Poses per packet: one per lane.
constexpr int kPoses = kWidth;

// The coordinates of a packet's poses, q[c] lane p = coordinate c of pose p (lanes past the
// batch's end hold home).
struct PosePacket {
  lane_v q[6];
};

// Lane p = r[6 p] (a column of the rows), built in registers: through a buffer, scalar stores
// followed by a vector load stall on store forwarding.
inline lane_v column(const double* r) noexcept {
#if HEXATWIST_LANE_WIDTH == 8
  return lane_v{r[0], r[6], r[12], r[18], r[24], r[30], r[36], r[42]};
#elif HEXATWIST_LANE_WIDTH == 4
  return lane_v{r[0], r[6], r[12], r[18]};
#else
  return lane_v{r[0], r[6]};
#endif
}

PosePacket load_poses(const double* rows, int n) noexcept {
  PosePacket out;
  if (n == kPoses) {
    for (int c = 0; c < 6; ++c) out.q[c] = column(rows + c);
    return out;
  }
  double padded[6 * kPoses] = {};  // the batch's last poses, then home
  std::memcpy(padded, rows, sizeof(double) * 6 * static_cast<std::size_t>(n));
  for (int c = 0; c < 6; ++c) out.q[c] = column(padded + c);
  return out;
}

// Writes lane p of v[i] to rows[6 p + i] for the lanes of `write` (p < n).
void store_rows(const lane_v (&v)[kLegs], unsigned write, int n, double* rows) noexcept {
  alignas(64) double t[kLegs][kPoses];
  std::memcpy(t, v, sizeof t);
  for (int p = 0; p < n; ++p)
    if (write >> p & 1u)
      for (int i = 0; i < kLegs; ++i) rows[6 * p + i] = t[i][p];
}

// One bit per lane of a mask.
unsigned lane_bits(lane_m m) noexcept {
  unsigned bits = 0;
  for (int p = 0; p < kPoses; ++p) bits |= (m[p] != 0 ? 1u : 0u) << p;
  return bits;
}

// Lanes the packet can compute as the single pose does: finite, and angles below 1e5 rad (beyond,
// sin_cos of fast_math.hpp falls back to libm).
lane_m computable(const PosePacket& p) noexcept {
  lane_m ok = all_set();
  for (int c = 0; c < 3; ++c) ok &= p.q[c] * 0.0 == 0.0;  // NaN and inf fail
  for (int c = 3; c < 6; ++c) ok &= vabs(p.q[c]) < 1e5;
  return ok;
}

// Eq. (3) per lane. For |angle| <= 0.78 the full sin_cos reduces with k = 0 exactly, which is what
// the single pose's shortcut (sin_cos_reduced) computes.
[[gnu::always_inline]] inline LaneRotation<lane_v> rotation_of(const PosePacket& p) noexcept {
  lane_v s[3], c[3];
  for (int k = 0; k < 3; ++k) sin_cos(p.q[3 + k], s[k], c[k]);
  return rotation_rzyx(s[0], c[0], s[1], c[1], s[2], c[2]);
}

// The platform's origin pivot_home + t per lane, as legs_at adds them for one pose.
lanes3 origin_of(const Model& model, const PosePacket& p) noexcept {
  const Vector3d& pivot = model.pivot_home_B();
  return {pivot.x() + p.q[0], pivot.y() + p.q[1], pivot.z() + p.q[2]};
}

// Leg i's numbers of the model's LegLanes in every lane.
lane_v every_lane(const double (&a)[8], int i) noexcept { return splat<lane_v>(a[i]); }
lanes3 every_lane(const double (&a)[3][8], int i) noexcept {
  return {splat<lane_v>(a[0][i]), splat<lane_v>(a[1][i]), splat<lane_v>(a[2][i])};
}

// The sum of the legs' bounds on the twist's share in the order sum_lanes adds the real-time
// call's lanes: with two-lane packets, legs (0, 2, 4) and (1, 3, 5); else (0, 4, 2) and (1, 5, 3).
lane_v sum_of_legs(const lane_v (&t)[kLegs]) noexcept {
#if HEXATWIST_LANE_WIDTH == 2
  return ((t[0] + t[2]) + t[4]) + ((t[1] + t[3]) + t[5]);
#else
  return ((t[0] + t[4]) + t[2]) + ((t[1] + t[5]) + t[3]);
#endif
}

// commands_in_lanes (compensation.cpp) for a packet of poses: the travel commands of each leg
// (command[i], lane p: pose p) and the lanes that passed every test, the condition proof included.
lane_m commands_packet(const Model& model, const PosePacket& p, bool compensated, lane_v (&command)[kLegs]) noexcept {
  const LegLanes& g = model.geometry().lanes;
  const LaneRotation<lane_v> R = rotation_of(p);
  const lanes3 origin = origin_of(model, p);
  const bool twist_model = model.has_twist();
  const lane_v inv_condition_length = splat<lane_v>(1.0 / model.condition_length());
  lane_m ok = computable(p);
  lane_v share[kLegs];
  lane_v A[6][6];  // the scaled geometric Jacobian, row i = leg i
  for (int i = 0; i < kLegs; ++i) {
    const LegsAt legs =
        legs_at(R, origin, every_lane(g.arm_P, i), every_lane(g.axis_platform_P, i), every_lane(g.base_B, i));
    const lanes3 ja = every_lane(g.axis_base_B, i);
    const lanes3& jd = legs.axis_platform;
    const lane_v dot_a = dot(legs.leg, ja), dot_d = dot(legs.leg, jd);
    ok &= within_limits(model,
                        limit_terms(R, legs.leg, legs.length, legs.length, dot_a, dot_d, every_lane(g.s_home_B, i)));
    lane_v command_i = legs.length - every_lane(g.length_offset, i);
    const lane_v inv_length = 1.0 / legs.length;
    share[i] = lane_v{};
    if (twist_model) {
      const lane_v has_axes = every_lane(g.has_axes, i);
      const TwistTerms t = twist_terms(legs.leg, ja, jd, dot_a, dot_d, legs.length2);
      const lane_v y = legs.length * t.y;
      ok &= twist_regular(t.x, y, legs.length2 * legs.length2, has_axes);
      share[i] = twist_share_bound(model, t.x, y, dot_a, dot_d, legs.length, legs.length2, inv_length, has_axes,
                                   every_lane(g.arm_ratio, i), every_lane(g.twist_gain_bound, i));
      if (compensated) {
        command_i -= every_lane(g.twist_gain, i) * twist_angle(t.x, y, every_lane(g.cos_theta_home, i),
                                                               every_lane(g.sin_theta_home, i), has_axes);  // Eq. (12)
        ok &= within_stroke(model, command_i);
      }
    }
    command[i] = command_i;
    const lanes3 s = inv_length * legs.leg;
    const lanes3 arm_x_s = inv_condition_length * cross(legs.arm, s);
    const lane_v row[6] = {s.x, s.y, s.z, arm_x_s.x, arm_x_s.y, arm_x_s.z};
    for (int c = 0; c < 6; ++c) A[i][c] = row[c];
  }
  if (lane_bits(ok) == 0) return ok;
  const lane_v perturbation = sum_of_legs(share) * (1.0 + 1e-6) + 1e-13;
  return ok & condition_below_lanes(A, model.condition_reference(), model.condition_max_accepted(), perturbation, ok);
}

// Model::motor_from_travel per lane: h + (u - h) / s, leg by leg.
void motor_from_travel(const Model& model, lane_v (&command)[kLegs]) noexcept {
  if (!model.has_drive_scale()) return;
  const LegGeometry& geo = model.geometry();
  for (int i = 0; i < kLegs; ++i) {
    const lane_v h = splat<lane_v>(geo.home_command[i]);
    command[i] = h + (command[i] - h) / splat<lane_v>(geo.drive_scale[i]);
  }
}

Pose pose_of(const double* row) noexcept {
  Pose pose;
  pose.position = Vector3d(row[0], row[1], row[2]);
  pose.rpy = Vector3d(row[3], row[4], row[5]);
  return pose;
}

void fill_nan(double* row) noexcept {
  for (int i = 0; i < kLegs; ++i) row[i] = NAN;
}

}  // namespace

Status motor_commands_batch(const Model& model, std::span<const double> poses, Strategy strategy,
                            std::span<double> commands, std::span<LimitReport> reports) noexcept {
  const std::size_t n = reports.size();
  if (poses.size() != 6 * n || commands.size() != 6 * n) return Status::MalformedInput;
  if (strategy == Strategy::Compensated && model.has_leg_effects()) {
    // The legs' effects (the static load's deflection at the pose, the play of the approach from
    // home, kinematics/leg_effects.hpp) are not in the lanes: motor_commands pose by pose.
    for (std::size_t p = 0; p < n; ++p) {
      Vector6d c;
      if (motor_commands(model, pose_of(poses.data() + 6 * p), strategy, c, reports[p]) == Status::Ok)
        std::memcpy(commands.data() + 6 * p, c.data(), sizeof(double) * kLegs);
      else
        fill_nan(commands.data() + 6 * p);
    }
    return Status::Ok;
  }
  const bool compensated = strategy == Strategy::Compensated && model.has_twist();
  for (std::size_t first = 0; first < n; first += kPoses) {
    const int count = static_cast<int>(std::min<std::size_t>(kPoses, n - first));
    const double* rows = poses.data() + 6 * first;
    double* out = commands.data() + 6 * first;
    const PosePacket packet = load_poses(rows, count);
    lane_v command[kLegs];
    const unsigned ok = lane_bits(commands_packet(model, packet, compensated, command));
    motor_from_travel(model, command);
    store_rows(command, ok, count, out);
    const unsigned computed = lane_bits(computable(packet));
    for (int p = 0; p < count; ++p) {
      LimitReport& report = reports[first + static_cast<std::size_t>(p)];
      if (ok >> p & 1u) {
        report = LimitReport{};
        continue;
      }
      // A test failed (or the pose is not for the lanes): the single-pose path from where the
      // real-time call would take it, which names the leg and limit.
      Vector6d c;
      const Pose pose = pose_of(rows + 6 * p);
      const Status s = computed >> p & 1u ? detail::commands_through_state(model, pose, compensated, c, report)
                                          : motor_commands(model, pose, strategy, c, report);
      if (s == Status::Ok)
        std::memcpy(out + 6 * p, c.data(), sizeof(double) * kLegs);
      else
        fill_nan(out + 6 * p);
    }
  }
  return Status::Ok;
}

Status leg_lengths_batch(const Model& model, std::span<const double> poses, std::span<double> lengths,
                         std::span<Status> status) noexcept {
  const std::size_t n = status.size();
  if (poses.size() != 6 * n || lengths.size() != 6 * n) return Status::MalformedInput;
  const LegLanes& g = model.geometry().lanes;
  for (std::size_t first = 0; first < n; first += kPoses) {
    const int count = static_cast<int>(std::min<std::size_t>(kPoses, n - first));
    const double* rows = poses.data() + 6 * first;
    double* out = lengths.data() + 6 * first;
    const PosePacket packet = load_poses(rows, count);
    const LaneRotation<lane_v> R = rotation_of(packet);
    const lanes3 origin = origin_of(model, packet);
    lane_m ok = computable(packet);
    lane_v length[kLegs];
    for (int i = 0; i < kLegs; ++i) {
      length[i] =
          legs_at(R, origin, every_lane(g.arm_P, i), every_lane(g.axis_platform_P, i), every_lane(g.base_B, i)).length;
      ok &= length[i] > 0.0;  // NaN fails
    }
    const unsigned good = lane_bits(ok);
    store_rows(length, good, count, out);
    for (int p = 0; p < count; ++p) {
      Status& s = status[first + static_cast<std::size_t>(p)];
      if (good >> p & 1u) {
        s = Status::Ok;
        continue;
      }
      LegState legs;  // inverse_kinematics names what the lanes could not
      s = inverse_kinematics(model, pose_of(rows + 6 * p), legs);
      if (s == Status::NonFiniteInput)
        fill_nan(out + 6 * p);
      else
        std::memcpy(out + 6 * p, legs.length.data(), sizeof(double) * kLegs);
    }
  }
  return Status::Ok;
}

}  // namespace hexatwist
