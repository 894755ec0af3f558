// SPDX-License-Identifier: BSD-3-Clause
// Batch inverse kinematics and twist over (N, 6) poses: leg lengths, unit axes, U-joint bends,
// twist relative to home and the length error it causes (Eq. 1-10); where a platform point is.
#include <cmath>

#include "common.hpp"

namespace hexatwist::python {
namespace {

// Leg lengths only, the poses across the lanes (batch.hpp).
py::dict lengths_batch(const Model& model, const Rows6& poses) {
  const std::size_t n = poses.rows;
  auto lengths = new_rows(n, 6, poses.single);
  auto status = new_column<std::int8_t>(n, poses.single);
  double* pl = lengths.mutable_data();
  std::int8_t* ps = status.mutable_data();
  const double* q = poses.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    constexpr std::size_t kChunk = 256;
    Status st[kChunk];
    for (std::size_t first = begin; first < end; first += kChunk) {
      const std::size_t m = std::min(kChunk, end - first);
      (void)leg_lengths_batch(model, {q + 6 * first, 6 * m}, {pl + 6 * first, 6 * m}, {st, m});  // consistent spans
      for (std::size_t i = 0; i < m; ++i) ps[first + i] = static_cast<std::int8_t>(st[i]);
    }
  });
  raise_non_finite(ps, n, "poses");
  py::dict d;
  d["lengths"] = lengths;
  d["status"] = status;
  return d;
}

py::dict ik_batch(const Model& model, const py::object& poses_in, bool lengths_only) {
  const Rows6 poses = rows6(poses_in, "poses");
  if (lengths_only) return lengths_batch(model, poses);
  const std::size_t n = poses.rows;
  auto lengths = new_rows(n, 6, poses.single);
  py::array_t<double> axes = poses.single
                                 ? py::array_t<double>({6, 3})
                                 : py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{6}, py::ssize_t{3}});
  auto bend_base = new_rows(n, 6, poses.single), bend_platform = new_rows(n, 6, poses.single);
  auto status = new_column<std::int8_t>(n, poses.single);
  double *pl = lengths.mutable_data(), *pa = axes.mutable_data(), *pb = bend_base.mutable_data(),
         *pp = bend_platform.mutable_data();
  std::int8_t* ps = status.mutable_data();
  const double* q = poses.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    LegState legs;
    Vector6d bb, bp;
    for (std::size_t i = begin; i < end; ++i) {
      const Status s = inverse_kinematics(model, pose_row(q, i), legs);
      ps[i] = static_cast<std::int8_t>(s);
      if (s == Status::NonFiniteInput) {
        for (int k = 0; k < 6; ++k) pl[6 * i + k] = pb[6 * i + k] = pp[6 * i + k] = NAN;
        for (int k = 0; k < 18; ++k) pa[18 * i + k] = NAN;
        continue;
      }
      bend_angles(model, legs, bb, bp);
      for (int k = 0; k < 6; ++k) {
        pl[6 * i + k] = legs.length[k];
        pb[6 * i + k] = bb[k];
        pp[6 * i + k] = bp[k];
        for (int c = 0; c < 3; ++c) pa[18 * i + 3 * k + c] = legs.s_B(k, c);
      }
    }
  });
  raise_non_finite(ps, n, "poses", poses.data);
  py::dict d;
  d["lengths"] = lengths;
  d["axes"] = axes;
  d["bend_base"] = bend_base;
  d["bend_platform"] = bend_platform;
  d["status"] = status;
  return d;
}

py::dict twist_batch(const Model& model, const py::object& poses_in) {
  const Rows6 poses = rows6(poses_in, "poses");
  const std::size_t n = poses.rows;
  auto tw = new_rows(n, 6, poses.single), err = new_rows(n, 6, poses.single);
  auto status = new_column<std::int8_t>(n, poses.single);
  double *pt = tw.mutable_data(), *pe = err.mutable_data();
  std::int8_t* ps = status.mutable_data();
  const double* q = poses.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    LegState legs;
    Vector6d dtheta, e;
    for (std::size_t i = begin; i < end; ++i) {
      Status s = inverse_kinematics(model, pose_row(q, i), legs);
      if (s == Status::Ok) s = twist(model, legs, dtheta);
      ps[i] = static_cast<std::int8_t>(s);
      if (s != Status::Ok) {
        for (int k = 0; k < 6; ++k) pt[6 * i + k] = pe[6 * i + k] = NAN;
        continue;
      }
      length_error(model, dtheta, e);
      for (int k = 0; k < 6; ++k) {
        pt[6 * i + k] = dtheta[k];
        pe[6 * i + k] = e[k];
      }
    }
  });
  raise_non_finite(ps, n, "poses", poses.data);
  py::dict d;
  d["twist"] = tw;
  d["length_error"] = err;
  d["status"] = status;
  return d;
}

// Where a platform point (given in P) is in the base frame at each pose: platform_point_B.
py::array_t<double> platform_points(const Model& model, const py::object& poses_in, const py::object& point_in) {
  const Rows6 poses = rows6(poses_in, "poses");
  const Vector3d p_P = point_in.is_none() ? model.spec().observation_P : vector3(point_in, "point");
  const std::size_t n = poses.rows;
  for (std::size_t i = 0; i < 6 * n; ++i)
    if (!std::isfinite(poses.data[i])) raise_input("poses: row " + std::to_string(i / 6) + " holds NaN or inf");
  auto out = new_rows(n, 3, poses.single);
  double* po = out.mutable_data();
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vector3d p_B = platform_point_B(model, placement_from_pose(pose_row(poses.data, i)), p_P);
      for (int k = 0; k < 3; ++k) po[3 * i + k] = p_B[k];
    }
  });
  return out;
}

}  // namespace

void expose_kinematics(py::module_& m) {
  m.def("_ik", &ik_batch, py::arg("model"), py::arg("poses"), py::arg("lengths_only") = false);
  m.def("_twist", &twist_batch, py::arg("model"), py::arg("poses"));
  m.def("_platform_points", &platform_points, py::arg("model"), py::arg("poses"), py::arg("point") = py::none());
}

}  // namespace hexatwist::python
