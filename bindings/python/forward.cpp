// Batch forward kinematics from (N, 6) leg lengths, motor-side (twist included) or geometric:
// warm-started along the batch (in fixed blocks, so the result does not depend on the threads) or
// from given guesses, with per-pose status, iterations and residual.
#include "common.hpp"

namespace hexatwist::python {
namespace {

py::dict fk_batch(const Model& model, const py::object& lengths_in, const std::string& kind_name,
                  const py::object& guess_in, int max_iterations, double tolerance) {
  const LengthKind kind = length_kind_from(kind_name);
  const Rows6 lengths = rows6(lengths_in, "lengths");
  const std::size_t n = lengths.rows;
  Rows6 guess;
  const bool chain = guess_in.is_none();
  if (!chain) {
    guess = rows6(guess_in, "guess");
    if (!guess.single && guess.rows != n)
      raise_input("guess: expected shape (6,) or (" + std::to_string(n) + ", 6) to match lengths, got (" +
                  std::to_string(guess.rows) + ", 6)");
    for (std::size_t i = 0; i < guess.rows * 6; ++i)
      if (!std::isfinite(guess.data[i])) raise_input("guess: row " + std::to_string(i / 6) + " holds NaN or inf");
  }
  if (max_iterations < 1) raise_input("max_iterations: must be at least 1");
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) raise_input("tolerance: must be a finite number > 0 [m]");
  FkOptions options;
  options.max_iterations = max_iterations;
  options.tolerance = tolerance;
  auto poses = new_rows(n, 6, lengths.single);
  auto status = new_column<std::int8_t>(n, lengths.single);
  auto iterations = new_column<std::int32_t>(n, lengths.single);
  auto residual = new_column<double>(n, lengths.single);
  double *pq = poses.mutable_data(), *pr = residual.mutable_data();
  std::int8_t* ps = status.mutable_data();
  std::int32_t* pi = iterations.mutable_data();
  const double* l = lengths.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    FkResult r;
    Placement start;  // home; then the last solution of this block
    for (std::size_t i = begin; i < end; ++i) {
      if (!chain) start = placement_from_pose(pose_row(guess.data, guess.single ? 0 : i));
      const Status s =
          forward_kinematics(model, Eigen::Map<const Vector6d>(l + 6 * i), kind, start, r, options);
      ps[i] = static_cast<std::int8_t>(s);
      pi[i] = r.iterations;
      pr[i] = r.residual;
      const Vector6d q = r.pose.to_vector();
      for (int k = 0; k < 6; ++k) pq[6 * i + k] = s == Status::Ok ? q[k] : NAN;
      if (chain && s == Status::Ok) start = r.placement;
    }
  });
  raise_non_finite(ps, n, "lengths");
  py::dict d;
  d["poses"] = poses;
  d["status"] = status;
  d["iterations"] = iterations;
  d["residual"] = residual;
  return d;
}

}  // namespace

void expose_forward(py::module_& m) {
  m.def("_forward", &fk_batch, py::arg("model"), py::arg("lengths"), py::arg("kind") = "motor",
        py::arg("guess") = py::none(), py::arg("max_iterations") = 30, py::arg("tolerance") = 1e-12);
  m.attr("BLOCK") = kBlock;
}

}  // namespace hexatwist::python
