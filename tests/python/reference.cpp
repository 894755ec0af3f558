// SPDX-License-Identifier: BSD-3-Clause
// The library called directly, pose by pose, for the Python tests to compare with bit for bit:
// reads N poses (raw float64, N x 6) from argv[1] and writes to argv[2], per pose, the IK lengths,
// the twist, the compensated and conventional commands (NaN unless ok) and the three statuses, as
// float64 rows of 6 + 6 + 6 + 6 + 3.
// With a mode first (`reference MODE in out`), the newer calls on the seed configuration:
//   dynamics      in: N x 18 (pose, pose rate, pose acceleration); out per row: the 12 parts of
//                 InverseDynamics (6 each, NaN unless ok), status, mass matrix (36, row-major),
//                 kinetic and potential energy, forward_dynamics for torque - friction (6)
//   sizing        in: a trajectory CSV; out: per sample time, torque, speed, power, the 6 terms
//                 (1 + 54), then per motor 15 numbers, then the first violation (6), then status
//   registration  in: N x 6 (p_T, p_B); out: status, R_BT (9, row-major), t_BT, rms, max, sigma, condition
//   axis_range    in: unused; out: per strategy (compensated, conventional) and coordinate: lower,
//                 upper, status of both limits, status
//   tracked       in: N x 6 motor-side lengths; out per row: pose (6), status, iterations, residual
//   mjcf          in: unused; out: the MJCF text of the seed rig
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/hexatwist.hpp"
#include "hexatwist/io/mjcf.hpp"

namespace {

using namespace hexatwist;

std::vector<double> read_doubles(const char* path) {
  std::vector<double> v;
  std::FILE* in = std::fopen(path, "rb");
  if (!in) return v;
  double x;
  while (std::fread(&x, sizeof(double), 1, in) == 1) v.push_back(x);
  std::fclose(in);
  return v;
}

int write_doubles(const char* path, const std::vector<double>& out) {
  std::FILE* o = std::fopen(path, "wb");
  if (!o) return 2;
  std::fwrite(out.data(), sizeof(double), out.size(), o);
  std::fclose(o);
  return 0;
}

void put(std::vector<double>& out, const Vector6d& v) { out.insert(out.end(), v.data(), v.data() + 6); }

int dynamics(const char* in, const char* path) {
  const Config config = default_config();
  const Rig& rig = config.rig;
  const std::vector<double> q = read_doubles(in);
  std::vector<double> out;
  for (std::size_t i = 0; i < q.size() / 18; ++i) {
    const double* r = &q[18 * i];
    const PlatformMotion m = platform_motion(Pose::from_vector(Eigen::Map<const Vector6d>(r)),
                                             Eigen::Map<const Vector6d>(r + 6), Eigen::Map<const Vector6d>(r + 12));
    InverseDynamics id;
    const Status s = inverse_dynamics(rig, m, id);
    for (const Vector6d* v :
         {&id.torque, &id.angle, &id.speed, &id.acceleration, &id.power, &id.gravity, &id.platform_inertia,
          &id.velocity_product, &id.legs, &id.drives, &id.friction, &id.screw_force})
      put(out, s == Status::Ok ? *v : Vector6d::Constant(NAN));
    out.push_back(static_cast<double>(s));
    Matrix6d M = Matrix6d::Constant(NAN);
    double ke = NAN, pe = NAN;
    Vector6d a = Vector6d::Constant(NAN);
    if (s == Status::Ok) {
      (void)mechanism_mass_matrix(rig, m.placement, M);
      (void)kinetic_energy(rig, m.placement, m.velocity, ke);
      (void)potential_energy(rig, m.placement, pe);
      (void)forward_dynamics(rig, m.placement, m.velocity, id.torque - id.friction, a);
    }
    for (int r2 = 0; r2 < 6; ++r2)
      for (int c = 0; c < 6; ++c) out.push_back(M(r2, c));
    out.push_back(ke);
    out.push_back(pe);
    put(out, a);
  }
  return write_doubles(path, out);
}

int sizing(const char* csv, const char* path) {
  const Config config = default_config();
  std::ifstream f(csv, std::ios::binary);
  std::ostringstream text;
  text << f.rdbuf();
  const Trajectory tr = resample(parse_trajectory_csv(text.str(), csv), config.rig.control_period());
  MotorSizing s;
  const Status status = size_motors(config.rig, tr, s);
  std::vector<double> out;
  for (const MotorSample& x : s.samples) {
    out.push_back(x.time);
    put(out, x.torque);
    put(out, x.speed);
    put(out, x.power);
    for (const Vector6d& t : x.terms) put(out, t);
  }
  for (const MotorSummary& m : s.motors) {
    out.insert(out.end(),
               {m.peak_torque, m.rms_torque, m.peak_speed, m.peak_power, m.energy_driven, m.energy_regenerated});
    out.insert(out.end(), m.share.begin(), m.share.end());
    out.insert(out.end(), {m.peak_usage, m.speed_usage, m.rms_usage});
  }
  const EnvelopeViolation& v = s.violation;
  out.insert(out.end(), {static_cast<double>(v.check), static_cast<double>(v.leg), static_cast<double>(v.index), v.time,
                         v.value, v.bound, static_cast<double>(status)});
  return write_doubles(path, out);
}

int registration(const char* in, const char* path) {
  const std::vector<double> q = read_doubles(in);
  std::vector<PointPair> pairs(q.size() / 6);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    pairs[i].p_T = Eigen::Map<const Vector3d>(&q[6 * i]);
    pairs[i].p_B = Eigen::Map<const Vector3d>(&q[6 * i + 3]);
  }
  Registration r;
  const Status s = register_points(pairs, r);
  std::vector<double> out{static_cast<double>(s)};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) out.push_back(r.X_BT.R(i, k));
  out.insert(out.end(), {r.X_BT.t[0], r.X_BT.t[1], r.X_BT.t[2], r.rms_residual, r.max_residual, r.sigma, r.condition});
  return write_doubles(path, out);
}

int ranges(const char* path) {
  const Model model = default_model();
  std::vector<double> out;
  for (Strategy st : {Strategy::Compensated, Strategy::Conventional})
    for (int k = 0; k < 6; ++k) {
      AxisRange r;
      const Status s = axis_range(model, k, st, r);
      out.insert(out.end(), {r.lower, r.upper, static_cast<double>(r.lower_limit.status),
                             static_cast<double>(r.upper_limit.status), static_cast<double>(s)});
    }
  return write_doubles(path, out);
}

int tracked(const char* in, const char* path) {
  const Model model = default_model();
  const std::vector<double> q = read_doubles(in);
  FkTracker tracker;
  FkResult r;
  std::vector<double> out;
  for (std::size_t i = 0; i < q.size() / 6; ++i) {
    const Status s =
        forward_kinematics_tracked(model, Eigen::Map<const Vector6d>(&q[6 * i]), LengthKind::Motor, tracker, r);
    put(out, s == Status::Ok ? r.pose.to_vector() : Vector6d::Constant(NAN));
    out.insert(out.end(), {static_cast<double>(s), static_cast<double>(r.iterations), r.residual});
  }
  return write_doubles(path, out);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace hexatwist;
  if (argc == 4) {
    const std::string mode = argv[1];
    if (mode == "dynamics") return dynamics(argv[2], argv[3]);
    if (mode == "sizing") return sizing(argv[2], argv[3]);
    if (mode == "registration") return registration(argv[2], argv[3]);
    if (mode == "axis_range") return ranges(argv[3]);
    if (mode == "tracked") return tracked(argv[2], argv[3]);
    if (mode == "mjcf") {
      const std::string text = mjcf_model(default_config().rig);
      std::FILE* o = std::fopen(argv[3], "wb");
      if (!o) return 2;
      std::fwrite(text.data(), 1, text.size(), o);
      std::fclose(o);
      return 0;
    }
    return 2;
  }
  if (argc != 3) return 2;
  std::FILE* in = std::fopen(argv[1], "rb");
  if (!in) return 2;
  std::vector<double> q;
  double buf[6];
  while (std::fread(buf, sizeof(double), 6, in) == 6) q.insert(q.end(), buf, buf + 6);
  std::fclose(in);
  const Model model = default_model();
  std::vector<double> out;
  for (std::size_t i = 0; i < q.size() / 6; ++i) {
    const Pose pose = Pose::from_vector(Eigen::Map<const Vector6d>(&q[6 * i]));
    LegState legs;
    Vector6d tw = Vector6d::Constant(NAN), comp = Vector6d::Constant(NAN), conv = Vector6d::Constant(NAN);
    Status s_ik = inverse_kinematics(model, pose, legs);
    Status s_tw = s_ik == Status::Ok ? twist(model, legs, tw) : s_ik;
    if (s_tw != Status::Ok) tw.setConstant(NAN);
    LimitReport r;
    Vector6d c;
    const Status s_comp = motor_commands(model, pose, Strategy::Compensated, c, r);
    if (s_comp == Status::Ok) comp = c;
    const Status s_conv = motor_commands(model, pose, Strategy::Conventional, c, r);
    if (s_conv == Status::Ok) conv = c;
    out.insert(out.end(), legs.length.data(), legs.length.data() + 6);
    out.insert(out.end(), tw.data(), tw.data() + 6);
    out.insert(out.end(), comp.data(), comp.data() + 6);
    out.insert(out.end(), conv.data(), conv.data() + 6);
    out.push_back(static_cast<double>(s_tw));
    out.push_back(static_cast<double>(s_comp));
    out.push_back(static_cast<double>(s_conv));
  }
  std::FILE* o = std::fopen(argv[2], "wb");
  if (!o) return 2;
  std::fwrite(out.data(), sizeof(double), out.size(), o);
  std::fclose(o);
  return 0;
}
