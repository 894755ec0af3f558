// SPDX-License-Identifier: BSD-3-Clause
// Tolerance analysis (design/tolerance.hpp): a range of sampled platforms (locally, or one chunk of
// a Dask study), the covariance answer's quantiles, and the summary of the whole study.
#include <pybind11/stl.h>

#include "common.hpp"
#include "hexatwist/design/tolerance_calibration.hpp"

namespace hexatwist::python {

std::vector<Pose> design_poses(const PlatformSource& p, const py::object& poses, const py::dict& required);

namespace {

ToleranceSigmas sigmas_of(const py::dict& d) {
  ToleranceSigmas s;
  const auto get = [&](const char* key, double& out) {
    if (!d.contains(key)) return;
    out = d[key].cast<double>();
  };
  for (const auto& kv : d) {
    const std::string k = kv.first.cast<std::string>();
    if (k != "base_joint" && k != "platform_joint" && k != "base_axis" && k != "platform_axis" && k != "lead" &&
        k != "offset")
      raise_input("sigmas: unknown key '" + k +
                  "'; expected base_joint, platform_joint [m], base_axis, platform_axis [rad], lead [-], offset [m]");
  }
  get("base_joint", s.base_joint);
  get("platform_joint", s.platform_joint);
  get("base_axis", s.base_axis);
  get("platform_axis", s.platform_axis);
  get("lead", s.lead);
  get("offset", s.offset);
  check_tolerance_sigmas(s);  // the library's ranges: InputError naming the key
  return s;
}

template <class T>
py::array_t<T> array_of(const std::vector<T>& v) {
  return py::array_t<T>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::dict chunk_dict(const ToleranceChunk& c) {
  py::dict d;
  d["first"] = c.first;
  d["max_point"] = array_of(c.max_point);
  d["rms_point"] = array_of(c.rms_point);
  d["max_position"] = array_of(c.max_position);
  d["max_orientation"] = array_of(c.max_orientation);
  d["max_point_linear"] = array_of(c.max_point_linear);
  d["failures"] = array_of(c.failures);
  d["calibration"] = array_of(c.calibration);
  d["histogram_point"] = array_of(c.point.counts);
  d["histogram_position"] = array_of(c.position.counts);
  d["histogram_orientation"] = array_of(c.orientation.counts);
  return d;
}

template <class T>
std::vector<T> vector_of(const py::handle& a, const char* name) {
  const auto arr = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!arr || arr.ndim() != 1) raise_input(std::string("chunk: ") + name + " must be a 1-D array");
  return std::vector<T>(arr.data(), arr.data() + arr.size());
}

ToleranceChunk chunk_of(const py::dict& d) {
  ToleranceChunk c;
  c.first = d["first"].cast<std::uint64_t>();
  c.max_point = vector_of<double>(d["max_point"], "max_point");
  c.rms_point = vector_of<double>(d["rms_point"], "rms_point");
  c.max_position = vector_of<double>(d["max_position"], "max_position");
  c.max_orientation = vector_of<double>(d["max_orientation"], "max_orientation");
  c.max_point_linear = vector_of<double>(d["max_point_linear"], "max_point_linear");
  c.failures = vector_of<std::uint32_t>(d["failures"], "failures");
  c.calibration = d.contains("calibration") ? vector_of<std::uint8_t>(d["calibration"], "calibration")
                                            : std::vector<std::uint8_t>(c.failures.size(), 0);
  c.point.counts = vector_of<std::uint64_t>(d["histogram_point"], "histogram_point");
  c.position.counts = vector_of<std::uint64_t>(d["histogram_position"], "histogram_position");
  c.orientation.counts = vector_of<std::uint64_t>(d["histogram_orientation"], "histogram_orientation");
  const std::size_t n = c.max_point.size();
  if (c.rms_point.size() != n || c.max_position.size() != n || c.max_orientation.size() != n ||
      c.max_point_linear.size() != n || c.failures.size() != n || c.calibration.size() != n)
    raise_input("chunk: the per-platform arrays differ in length");
  for (const auto* h : {&c.point.counts, &c.position.counts, &c.orientation.counts})
    if (h->size() != static_cast<std::size_t>(ErrorHistogram::kBins))
      raise_input("chunk: a histogram has the wrong size");
  return c;
}

// The calibration `calibration` names, its tracker from `tracker` (noise [m], points_per_station,
// frames "tracker" or "joints", stations: the plan's poses (N, 6) [m, rad from home]).
CalibrationChoice choice_of(const std::string& calibration, const py::object& tracker) {
  CalibrationChoice c;
  c.name = calibration;
  if (tracker.is_none()) return c;
  if (!is_tracker_calibration(calibration))
    raise_input(
        "tracker: only with a tracker calibration (calibration=\"stations:N[,SEED]\" or \"plan\"), not with "
        "calibration=\"" +
        calibration + "\"");
  const py::dict t = tracker;
  for (const auto& kv : t) {
    const std::string k = kv.first.cast<std::string>();
    if (k != "noise" && k != "points_per_station" && k != "frames" && k != "stations" && k != "targets")
      raise_input("tracker: unknown key '" + k +
                  "'; expected noise [m], points_per_station, frames, stations, targets [m, platform]");
  }
  if (t.contains("noise")) c.tracker_noise = t["noise"].cast<double>();
  if (t.contains("points_per_station")) c.points = t["points_per_station"].cast<int>();
  if (t.contains("frames")) {
    const std::string f = t["frames"].cast<std::string>();
    if (f != "tracker" && f != "joints") raise_input("tracker: frames must be 'tracker' or 'joints', got '" + f + "'");
    c.frames = f == "joints" ? CalibratedFrames::Joints : CalibratedFrames::Tracker;
  }
  if (t.contains("stations") && !t["stations"].is_none()) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(t["stations"]);
    if (!a || a.ndim() != 2 || a.shape(1) != 6) raise_input("tracker: stations must be an (N, 6) array [m, rad]");
    for (py::ssize_t r = 0; r < a.shape(0); ++r) c.plan.push_back(Eigen::Map<const Vector6d>(a.data(r, 0)));
  }
  if (t.contains("targets") && !t["targets"].is_none()) {  // the library checks them (check_tracker_calibration)
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(t["targets"]);
    if (!a || (!(a.ndim() == 2 && a.shape(1) == 3) && !(a.ndim() == 1 && a.shape(0) == 0)))
      raise_input("tracker: targets must be an (N, 3) array [m, platform]");
    for (py::ssize_t r = 0; a.ndim() == 2 && r < a.shape(0); ++r)
      c.extra_targets_P.push_back(Eigen::Map<const Vector3d>(a.data(r, 0)));
  }
  return c;
}

[[noreturn]] void raise_study_status(Status s) {
  raise_status(s, s == Status::NotIdentifiable ? "tolerance: the station plan does not determine the parameters"
                                               : "tolerance: a pose outside the nominal workspace");
}

// What every study call reads: the platform, the required poses, the options' sigmas, seed and threads.
struct StudyInputs {
  PlatformSource p;
  std::vector<Pose> poses;
  ToleranceOptions o;
};

StudyInputs study_inputs(const py::object& config, const py::object& poses_in, const py::dict& required,
                         const py::dict& sigmas, std::uint64_t seed, int threads) {
  StudyInputs in{platform_of(config), {}, {}};
  in.poses = design_poses(in.p, poses_in, required);
  in.o.sigmas = sigmas_of(sigmas);
  in.o.seed = seed;
  in.o.threads = threads;
  return in;
}

// Platforms [first, first + count) of the study.
py::dict chunk_py(const py::object& config, const py::object& poses_in, const py::dict& required,
                  const py::dict& sigmas, std::uint64_t seed, std::uint64_t first, std::size_t count,
                  const std::string& calibration, bool linear_worst, int threads, const py::object& tracker) {
  StudyInputs in = study_inputs(config, poses_in, required, sigmas, seed, threads);
  const auto& [p, poses, o] = in;
  in.o.linear_worst = linear_worst;
  const CalibrationChoice choice = choice_of(calibration, tracker);
  ToleranceLinear linear;
  ToleranceChunk c;
  Status s = Status::Ok;
  {
    py::gil_scoped_release release;
    // The calibration step and its linear model (prepare_calibration throws for a bad choice).
    s = prepare_calibration(*p.model, poses, choice, in.o, linear);
    if (s == Status::Ok) s = tolerance_chunk(*p.model, poses, o, first, count, c, linear_worst ? &linear : nullptr);
  }
  if (s != Status::Ok) raise_study_status(s);
  return chunk_dict(c);
}

py::dict quantiles_dict(const ErrorQuantiles& q) {
  py::dict d;
  d["median"] = q.median;
  d["p95"] = q.p95;
  d["max"] = q.max;
  return d;
}

// The covariance answer: median and p95 of point, position and orientation errors.
py::dict linear_py(const py::object& config, const py::object& poses_in, const py::dict& required,
                   const py::dict& sigmas, int threads, const std::string& calibration, const py::object& tracker,
                   std::uint64_t seed) {
  StudyInputs in = study_inputs(config, poses_in, required, sigmas, seed, threads);
  const auto& [p, poses, o] = in;
  const CalibrationChoice choice = choice_of(calibration, tracker);
  ToleranceLinear linear;
  ToleranceSummary summary;
  Status st;
  {
    py::gil_scoped_release release;
    st = prepare_calibration(*p.model, poses, choice, in.o, linear);
    if (st == Status::Ok) linear_quantiles(linear, summary, threads);
  }
  if (st != Status::Ok) raise_study_status(st);
  py::dict d;
  d["point"] = quantiles_dict(summary.point_linear);
  d["position"] = quantiles_dict(summary.position_linear);
  d["orientation"] = quantiles_dict(summary.orientation_linear);
  d["poses"] = poses.size();
  return d;
}

// The layouts of 0..max_extra extra targets (target_layouts) for the tracker calibration `calibration`.
py::list layouts_py(const py::object& config, const py::object& poses_in, const py::dict& required,
                    const py::dict& sigmas, int threads, const std::string& calibration, const py::object& tracker,
                    std::uint64_t seed, int max_extra) {
  const StudyInputs in = study_inputs(config, poses_in, required, sigmas, seed, threads);
  const auto& [p, poses, o] = in;
  if (!is_tracker_calibration(calibration))
    raise_input(
        "target_layouts: calibration must be a tracker calibration (\"stations:N[,SEED]\" or \"plan\"), got \"" +
        calibration + "\"");
  const TrackerCalibration c = tracker_calibration_of(*p.model, choice_of(calibration, tracker), seed);
  std::vector<TargetLayout> layouts;
  {
    py::gil_scoped_release release;
    layouts = target_layouts(*p.model, poses, o, c, max_extra);
  }
  py::list out;
  for (const TargetLayout& l : layouts) {
    py::dict d;
    py::array_t<double> t({static_cast<py::ssize_t>(l.extra_targets_P.size()), py::ssize_t{3}});
    for (std::size_t k = 0; k < l.extra_targets_P.size(); ++k)
      for (int a = 0; a < 3; ++a) t.mutable_at(static_cast<py::ssize_t>(k), a) = l.extra_targets_P[k][a];
    d["extra_targets"] = t;
    d["status"] = std::string(to_string(l.status));
    d["point"] = quantiles_dict(l.point);
    d["position"] = quantiles_dict(l.position);
    d["orientation"] = quantiles_dict(l.orientation);
    out.append(d);
  }
  return out;
}

ErrorQuantiles quantiles_of(const py::dict& d) {
  ErrorQuantiles q;
  q.median = d["median"].cast<double>();
  q.p95 = d["p95"].cast<double>();
  q.max = d["max"].is_none() ? NAN : d["max"].cast<double>();
  return q;
}

py::dict summary_py(const py::dict& chunk, std::size_t poses, const py::object& linear) {
  const ToleranceChunk c = chunk_of(chunk);
  ToleranceSummary s = summarize_tolerance(c, poses, nullptr);
  if (!linear.is_none()) {
    const py::dict l = linear;
    s.point_linear = quantiles_of(l["point"]);
    s.position_linear = quantiles_of(l["position"]);
    s.orientation_linear = quantiles_of(l["orientation"]);
  }
  py::dict d;
  d["platforms"] = s.platforms;
  d["poses"] = s.poses;
  d["failures"] = s.failures;
  const std::pair<const char*, const ErrorQuantiles*> quantiles[] = {{"point", &s.point},
                                                                     {"position", &s.position},
                                                                     {"orientation", &s.orientation},
                                                                     {"point_linear", &s.point_linear},
                                                                     {"position_linear", &s.position_linear},
                                                                     {"orientation_linear", &s.orientation_linear},
                                                                     {"worst_point", &s.worst_point},
                                                                     {"worst_point_linear", &s.worst_point_linear},
                                                                     {"worst_position", &s.worst_position},
                                                                     {"worst_orientation", &s.worst_orientation}};
  for (const auto& [key, q] : quantiles) d[key] = quantiles_dict(*q);
  return d;
}

}  // namespace

void expose_tolerance(py::module_& m) {
  m.def("_tolerance_chunk", &chunk_py, py::arg("platform"), py::arg("poses"), py::arg("required"), py::arg("sigmas"),
        py::arg("seed"), py::arg("first"), py::arg("count"), py::arg("calibration") = "none",
        py::arg("linear_worst") = true, py::arg("threads") = 1, py::arg("tracker") = py::none());
  m.def("_tolerance_linear", &linear_py, py::arg("platform"), py::arg("poses"), py::arg("required"), py::arg("sigmas"),
        py::arg("threads") = 1, py::arg("calibration") = "none", py::arg("tracker") = py::none(), py::arg("seed") = 1);
  m.def("_tolerance_summary", &summary_py, py::arg("chunk"), py::arg("poses"), py::arg("linear"));
  m.def("_target_layouts", &layouts_py, py::arg("platform"), py::arg("poses"), py::arg("required"), py::arg("sigmas"),
        py::arg("threads"), py::arg("calibration"), py::arg("tracker"), py::arg("seed"), py::arg("max_extra"));
  m.attr("HISTOGRAM_BINS") = ErrorHistogram::kBins;
}

}  // namespace hexatwist::python
