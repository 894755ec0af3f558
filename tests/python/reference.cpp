// The library called directly, pose by pose, for the Python tests to compare with bit for bit:
// reads N poses (raw float64, N x 6) from argv[1] and writes to argv[2], per pose, the IK lengths,
// the twist, the compensated and conventional commands (NaN unless ok) and the three statuses, as
// float64 rows of 6 + 6 + 6 + 6 + 3.
#include <cmath>
#include <cstdio>
#include <vector>

#include "hexatwist/hexatwist.hpp"

int main(int argc, char** argv) {
  using namespace hexatwist;
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
