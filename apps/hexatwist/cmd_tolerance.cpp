// SPDX-License-Identifier: BSD-3-Clause
// hexatwist tolerance: how accurate a platform built with manufacturing errors is, before it is built
// (design/tolerance.hpp): the Monte Carlo over sampled platforms driven by the nominal compensated
// commands, beside the linearised (covariance) answer; on this machine or a Dask cluster.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <memory>

#include "cli_common.hpp"
#include "cluster.hpp"
#include "design_options.hpp"
#include "figures.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "progress.hpp"
#include "schemas.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

// On a terminal, the Monte Carlo runs in this many parts, the progress line redrawn after each.
constexpr std::uint64_t kProgressParts = 100;

namespace fs = std::filesystem;

struct ToleranceCommandOptions {
  ModelOptions model;
  RequiredOptions required;
  std::uint64_t platforms = 1000;
  std::uint64_t seed = 1;
  double joint_um = 50.0;
  double base_joint_um = NAN, platform_joint_um = NAN;
  double axis_deg = 0.1;
  double lead_ppm = 50.0;
  double offset_um = 100.0;
  std::string calibration = "none";
  double tracker_noise_um = 10.0;
  int points_per_station = 50;
  std::string calibration_frames = "tracker";
  std::string targets_mm;
  int target_layouts = 0;
  std::string station_plan;
  std::string out = "tolerance-out";
  std::string scheduler;
  bool json = false;
  bool no_figures = false;
  bool no_csv = false;
};

ToleranceSigmas sigmas_of(const ToleranceCommandOptions& o) {
  const bool base = !std::isnan(o.base_joint_um), platform = !std::isnan(o.platform_joint_um);
  ToleranceSigmas s;
  s.base_joint = 1e-6 * (base ? o.base_joint_um : o.joint_um);
  s.platform_joint = 1e-6 * (platform ? o.platform_joint_um : o.joint_um);
  s.base_axis = s.platform_axis = deg2rad(o.axis_deg);
  s.lead = 1e-6 * o.lead_ppm;
  s.offset = 1e-6 * o.offset_um;
  // The library's ranges (check_tolerance_sigmas), each field named as the option that set it.
  try {
    check_tolerance_sigmas(s);
  } catch (const ParameterError& e) {
    const std::string& f = e.parameter();
    const auto [option, typed] =
        f == "base_joint"
            ? std::pair{base ? "--sigma-base-joint-um" : "--sigma-joint-um", base ? o.base_joint_um : o.joint_um}
        : f == "platform_joint" ? std::pair{platform ? "--sigma-platform-joint-um" : "--sigma-joint-um",
                                            platform ? o.platform_joint_um : o.joint_um}
        : f == "lead"   ? std::pair{"--sigma-lead-ppm", o.lead_ppm}
        : f == "offset" ? std::pair{"--sigma-offset-um", o.offset_um}
                        : std::pair{"--sigma-axis-deg", o.axis_deg};
    throw ExitError(kExitBadInput, fmt::format("{} {:g}: {}", option, typed, e.what()));
  }
  return s;
}

void sigmas_json(JsonWriter& j, const ToleranceSigmas& s) {
  j.begin_object();
  j.field("base_joint", s.base_joint).field("platform_joint", s.platform_joint);
  j.field("base_axis", s.base_axis).field("platform_axis", s.platform_axis);
  j.field("lead", s.lead).field("offset", s.offset);
  j.end_object();
}

// The calibration the options name (its name checked by the library's prepare_calibration).
CalibrationChoice calibration_of(const ToleranceCommandOptions& o) {
  CalibrationChoice c;
  c.name = o.calibration;
  c.tracker_noise = o.tracker_noise_um / 1e6;  // correctly rounded: 20 um is 20e-6 m
  c.points = o.points_per_station;             // both checked by the library (check_tracker_calibration)
  c.frames = o.calibration_frames == "joints" ? CalibratedFrames::Joints : CalibratedFrames::Tracker;
  c.extra_targets_P = targets_option(o.targets_mm);
  if (!o.station_plan.empty()) {
    if (o.calibration != "none" && o.calibration != "plan")
      throw ExitError(kExitBadInput, fmt::format("--station-plan: a plan is its own calibration; --calibration is "
                                                 "'{}' (leave it out, or give plan)",
                                                 printable(o.calibration)));
    const std::string text = read_text_file(o.station_plan, "--station-plan", "stations run CSV file", kMaxDataBytes);
    try {
      c.plan = run_stations(parse_trajectory_csv(text, o.station_plan));
    } catch (const Error& e) {
      throw ExitError(kExitBadInput, fmt::format("--station-plan: {}", e.what()));
    }
    if (c.plan.empty())
      throw ExitError(kExitBadInput,
                      fmt::format("--station-plan: {} holds no pose for two samples in a row (no station)",
                                  printable(o.station_plan)));
    c.name = "plan";
  }
  return c;
}

bool tracker_calibration(const CalibrationChoice& c) { return is_tracker_calibration(c.name); }

void tracker_json(JsonWriter& j, const ToleranceCommandOptions& o, const CalibrationChoice& c) {
  if (!tracker_calibration(c)) {
    j.null();
    return;
  }
  j.begin_object().field("noise", c.tracker_noise).field("points_per_station", c.points);
  j.field("frames", o.calibration_frames);
  if (c.name == "plan") {  // the stations read [m, rad from home]
    j.key("stations").begin_array();
    for (const Vector6d& q : c.plan) {
      j.begin_array();
      for (int k = 0; k < 6; ++k) j.value(q[k]);
      j.end_array();
    }
    j.end_array();
  }
  if (!c.extra_targets_P.empty()) {  // besides point A [m, P]
    j.key("targets").begin_array();
    for (const Vector3d& t : c.extra_targets_P) j.vector(t);
    j.end_array();
  }
  j.end_object();
}

// The Monte Carlo on the cluster: platforms sampled and evaluated on the workers, their summaries here.
ToleranceChunk chunk_on_cluster(const ToleranceCommandOptions& o, const RequiredPoses& req, const ToleranceSigmas& s,
                                const CalibrationChoice& calibration, int& workers) {
  JsonWriter j;
  j.begin_object();
  j.field("job", "tolerance");
  j.field("scheduler", o.scheduler);
  j.key("config");
  if (o.model.config.empty())
    j.null();
  else
    j.value(read_text_file(o.model.config, "--config", "configuration", kMaxConfigBytes));
  j.key("workspace");
  write_spec_json(j, req.spec);
  if (!req.from_spec) {
    j.key("poses").begin_array();
    for (const Pose& p : req.poses) j.vector(p.to_vector());
    j.end_array();
  }
  j.key("sigmas");
  sigmas_json(j, s);
  j.field("seed", o.seed);
  j.field("platforms", o.platforms);
  j.field("calibration", calibration.name);
  j.key("tracker");
  tracker_json(j, o, calibration);
  j.field("timeout", 10);
  j.end_object();
  const ClusterArrays a = run_cluster_job(o.scheduler, j.str());
  workers = static_cast<int>(cluster_array(a, "workers", 1)[0]);
  const std::size_t n = o.platforms;
  ToleranceChunk c;
  c.first = static_cast<std::uint64_t>(cluster_array(a, "first", 1)[0]);
  c.max_point = cluster_array(a, "max_point", n);
  c.rms_point = cluster_array(a, "rms_point", n);
  c.max_position = cluster_array(a, "max_position", n);
  c.max_orientation = cluster_array(a, "max_orientation", n);
  c.max_point_linear = cluster_array(a, "max_point_linear", n);
  for (const double f : cluster_array(a, "failures", n)) c.failures.push_back(static_cast<std::uint32_t>(f));
  for (const double f : cluster_array(a, "calibration", n)) c.calibration.push_back(static_cast<std::uint8_t>(f));
  const auto histogram = [&](const char* name, ErrorHistogram& h) {
    const auto& v = cluster_array(a, name, static_cast<std::size_t>(ErrorHistogram::kBins));
    for (std::size_t k = 0; k < v.size(); ++k) h.counts[k] = static_cast<std::uint64_t>(v[k]);
  };
  histogram("histogram_point", c.point);
  histogram("histogram_position", c.position);
  histogram("histogram_orientation", c.orientation);
  return c;
}

void quantiles_json(JsonWriter& j, const ErrorQuantiles& q) {
  j.begin_object().field("median", q.median).field("p95", q.p95).field("max", q.max).end_object();
}

// The layouts of targets compared (--target-layouts): null without.
void layouts_json(JsonWriter& j, const std::vector<TargetLayout>& layouts) {
  if (layouts.empty()) {
    j.null();
    return;
  }
  j.begin_array();
  for (const TargetLayout& l : layouts) {
    j.begin_object().key("extra_targets").begin_array();
    for (const Vector3d& t : l.extra_targets_P) j.vector(t);
    j.end_array();
    j.field("status", std::string(to_string(l.status)));
    for (const auto& [key, q] :
         {std::pair{"point", &l.point}, {"position", &l.position}, {"orientation", &l.orientation}}) {
      j.key(key).begin_object();
      j.number_or_null("median", q->median, l.status == Status::Ok);
      j.number_or_null("p95", q->p95, l.status == Status::Ok);
      j.end_object();
    }
    j.end_object();
  }
  j.end_array();
}

std::string summary_json(const Model& model, const ToleranceCommandOptions& o, const RequiredPoses& req,
                         const ToleranceSigmas& s, const CalibrationChoice& calibration, const ToleranceSummary& sm,
                         const std::vector<TargetLayout>& layouts, int workers, double seconds,
                         const std::vector<std::string>& files) {
  JsonWriter j;
  j.begin_document(schema::kTolerance);
  j.field("command", "tolerance");
  j.field("units", "SI: m, rad; lead relative");
  j.field("config", model_source(o.model));
  j.field("model", model.spec().name);
  j.key("required_workspace");
  write_required_json(j, req);
  j.key("sigmas");
  sigmas_json(j, s);
  j.field("platforms", static_cast<std::uint64_t>(sm.platforms));
  j.field("poses", static_cast<std::uint64_t>(sm.poses));
  j.field("seed", o.seed);
  j.field("calibration", calibration.name);
  j.key("tracker");
  tracker_json(j, o, calibration);
  j.field("failures", sm.failures);
  j.key("calibration_failures").begin_object();  // platforms by the status of their calibration
  for (std::size_t k = 1; k < sm.calibration.size(); ++k)
    if (sm.calibration[k] > 0) j.field(std::string(to_string(static_cast<Status>(k))), sm.calibration[k]);
  j.end_object();
  // Each group of quantiles an object of its errors.
  const auto group = [&](const char* name, std::initializer_list<std::pair<const char*, const ErrorQuantiles*>> items) {
    j.key(name).begin_object();
    for (const auto& [key, q] : items) {
      j.key(key);
      quantiles_json(j, *q);
    }
    j.end_object();
  };
  group("monte_carlo", {{"point", &sm.point}, {"position", &sm.position}, {"orientation", &sm.orientation}});
  group("linearised",
        {{"point", &sm.point_linear}, {"position", &sm.position_linear}, {"orientation", &sm.orientation_linear}});
  group("worst_per_platform", {{"point", &sm.worst_point},
                               {"point_linear_model", &sm.worst_point_linear},
                               {"position", &sm.worst_position},
                               {"orientation", &sm.worst_orientation}});
  j.field("definitions",
          "pooled over every (platform, pose): the point A, pivot position and orientation (rotation angle) errors of "
          "the sampled platform driven by its controller's compensated commands (after a tracker calibration: in the "
          "frames tracker.frames names); linearised: the same from the covariance of the linear model; "
          "worst_per_platform: each platform's largest error over the poses; target_layouts (--target-layouts): "
          "the linearised median and 95th percentile after a calibration measuring point A and the extra targets "
          "[m, platform frame]");
  j.key("target_layouts");
  layouts_json(j, layouts);
  j.key("cluster");
  if (o.scheduler.empty())
    j.null();
  else
    j.begin_object().field("scheduler", o.scheduler).field("workers", workers).end_object();
  j.field("seconds", seconds);
  j.key("files").begin_array();
  for (const std::string& f : files) j.value(f);
  j.end_array();
  j.end_object();
  return j.str();
}

std::string platforms_csv(const ToleranceChunk& c) {
  std::string out =
      "platform,max_point_m,rms_point_m,max_position_m,max_orientation_rad,max_point_linear_m,failures,calibration\n";
  auto it = std::back_inserter(out);
  for (std::size_t k = 0; k < c.size(); ++k)
    fmt::format_to(it, "{},{},{},{},{},{},{},{}\n", c.first + k, c.max_point[k], c.rms_point[k], c.max_position[k],
                   c.max_orientation[k], c.max_point_linear[k], c.failures[k],
                   to_string(static_cast<Status>(c.calibration[k])));
  return out;
}

// Error values log-spaced over what the histogram holds (its 0.1 % to 99.9 % quantiles, widened).
std::vector<double> error_axis(const ErrorHistogram& h) {
  std::vector<double> r;
  const double lo = h.quantile(0.001), hi = h.quantile(0.999);
  if (!(lo > 0.0) || !(hi > lo)) return r;
  const double a = std::log(lo / 1.5), b = std::log(hi * 1.5);
  for (int k = 0; k <= 80; ++k) r.push_back(std::exp(a + (b - a) * k / 80.0));
  return r;
}

Panel cdf_panel(const std::string& title, const std::string& xlabel, double scale, const ErrorHistogram& h,
                const std::vector<Matrix3d>& covariances) {
  Panel p(title, xlabel, "share of (platform, pose) pairs [-]");
  const std::vector<double> r = error_axis(h);
  const std::vector<double> lin = gaussian_norm_mixture_cdf(covariances, r, 0);
  Series mc{"Monte Carlo (sampled platforms, forward kinematics)", {}, {}, Series::Style::Solid};
  Series li{"linearised (covariance of the linear model)", {}, {}, Series::Style::Dashed};
  for (std::size_t k = 0; k < r.size(); ++k) {
    mc.x.push_back(scale * r[k]);
    mc.y.push_back(h.cdf(r[k]));
    li.x.push_back(scale * r[k]);
    li.y.push_back(lin[k]);
  }
  p.series = {std::move(mc), std::move(li)};
  return p;
}

// The empirical distribution of each platform's worst error.
Series sorted_series(std::string label, std::vector<double> v, double scale, Series::Style style) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  std::sort(v.begin(), v.end());
  Series s{std::move(label), {}, {}, style};
  for (std::size_t k = 0; k < v.size(); ++k) {
    s.x.push_back(scale * v[k]);
    s.y.push_back((static_cast<double>(k) + 0.5) / static_cast<double>(v.size()));
  }
  return s;
}

// The figure; after a tracker calibration in micrometres and microradians.
Figure figure(const std::string& stem, const ToleranceChunk& c, const ToleranceLinear& lin, const ToleranceSummary& sm,
              bool calibrated) {
  Figure f{stem,
           fmt::format("Accuracy with manufacturing errors{}: {} platforms x {} poses",
                       calibrated ? ", after a tracker calibration" : "", sm.platforms, sm.poses),
           {}};
  const double scale = calibrated ? 1e6 : 1e3;
  const std::string mm = calibrated ? "um" : "mm", mrad = calibrated ? "urad" : "mrad";
  f.panels.push_back(cdf_panel("Error of point A over the workspace", "point A error [" + mm + "]", scale, c.point,
                               lin.point_covariance));
  f.panels.push_back(cdf_panel("Orientation error over the workspace", "orientation error [" + mrad + "]", scale,
                               c.orientation, lin.orientation_covariance));
  Panel worst("Each platform's largest point A error over the workspace", "largest point A error [" + mm + "]",
              "share of platforms [-]");
  worst.series.push_back(sorted_series("Monte Carlo", c.max_point, scale, Series::Style::Solid));
  worst.series.push_back(sorted_series("linear model, same errors", c.max_point_linear, scale, Series::Style::Dashed));
  f.panels.push_back(std::move(worst));
  return f;
}

std::string row(const char* what, const ErrorQuantiles& mc, const ErrorQuantiles& lin, double scale) {
  return fmt::format("{:<24}{:>10.4f}{:>10.4f}{:>10.4f}   {:>10.4f}{:>10.4f}   {:>7.3f}{:>7.3f}\n", what,
                     scale * mc.median, scale * mc.p95, scale * mc.max, scale * lin.median, scale * lin.p95,
                     mc.median / lin.median, mc.p95 / lin.p95);
}

// Who drives the platforms, for the report.
std::string controller_text(const ToleranceCommandOptions& o, const CalibrationChoice& c) {
  if (c.name == "none") return "the nominal compensated commands";
  if (c.name == "perfect") return "a perfectly calibrated controller's compensated commands";
  return fmt::format(
      "the compensated commands of each platform's controller after a tracker calibration ({}; {}{:g} um noise, {} "
      "points a station; errors in the {} frames)",
      c.name == "plan" ? fmt::format("{} stations of {}", c.plan.size(), printable(o.station_plan)) : c.name,
      c.extra_targets_P.empty() ? std::string()
                                : fmt::format("point A and {} more target{}, ", c.extra_targets_P.size(),
                                              c.extra_targets_P.size() == 1 ? "" : "s"),
      1e6 * c.tracker_noise, c.points, o.calibration_frames == "joints" ? "joints' least-squares" : "tracker's");
}

// The platforms whose calibration failed, by status.
std::string calibration_failures(const ToleranceSummary& sm) {
  std::uint64_t failed = 0;
  std::string by;
  for (std::size_t k = 1; k < sm.calibration.size(); ++k)
    if (sm.calibration[k] > 0) {
      failed += sm.calibration[k];
      by += fmt::format("{}{} {}", by.empty() ? "" : ", ", to_string(static_cast<Status>(k)), sm.calibration[k]);
    }
  if (failed == 0) return {};
  return fmt::format("calibration failed on {} of {} platforms ({}): all their poses count as failures\n", failed,
                     sm.platforms, by);
}

// Where to put the targets: each layout's linearised quantiles.
std::string layouts_text(const std::vector<TargetLayout>& layouts) {
  if (layouts.empty()) return {};
  std::string out =
      "\nwhere to put the targets: each layout calibrated from the same stations (the linearised answer, 95th "
      "percentile over the poses; the extra targets evenly spaced with point A on the circle through it about the "
      "pivot):\n";
  out += fmt::format("{:>7}  {:>12}  {:>10}  {:>18}  {}\n", "targets", "point A [um]", "pivot [um]",
                     "orientation [urad]", "extra targets x,y,z [mm, platform]");
  for (const TargetLayout& l : layouts) {
    std::string where;
    for (const Vector3d& t : l.extra_targets_P)
      where += fmt::format("{}{:.1f},{:.1f},{:.1f}", where.empty() ? "" : "; ", tidy(1e3 * t.x()), tidy(1e3 * t.y()),
                           tidy(1e3 * t.z()));
    if (where.empty()) where = "(point A alone)";
    if (l.status != Status::Ok)
      out += fmt::format("{:>7}  {:>44}  {}\n", l.extra_targets_P.size() + 1,
                         fmt::format("not determined ({})", to_string(l.status)), where);
    else
      out += fmt::format("{:>7}  {:>12.2f}  {:>10.2f}  {:>18.2f}  {}\n", l.extra_targets_P.size() + 1,
                         1e6 * l.point.p95, 1e6 * l.position.p95, 1e6 * l.orientation.p95, where);
  }
  out +=
      "(a tool point's error is at most the pivot's plus the orientation's times its distance from the pivot; "
      "give a layout with --targets-mm to see its Monte Carlo)\n";
  return out;
}

std::string report_text(const Model& model, const ToleranceCommandOptions& o, const RequiredPoses& req,
                        const ToleranceSigmas& s, const CalibrationChoice& c, const ToleranceSummary& sm,
                        const std::vector<TargetLayout>& layouts, int workers, double seconds,
                        const std::string& defaults) {
  std::string out =
      fmt::format("hexatwist tolerance on {}: {}{}\n", model_source(o.model), model.spec().name, defaults);
  out += fmt::format("required workspace: {}\n", req.description);
  out += fmt::format(
      "manufacturing errors (standard deviations, every leg): joint centres {:g} um (base), {:g} um (platform) per "
      "axis; U-joint axes {:g} deg; lead {:g} ppm; zero offsets {:g} um\n",
      1e6 * s.base_joint, 1e6 * s.platform_joint, rad2deg(s.base_axis), 1e6 * s.lead, 1e6 * s.offset);
  out +=
      fmt::format("{} platforms (seed {}) x {} poses, driven by {}{} in {:.1f} s\n", sm.platforms, o.seed, sm.poses,
                  controller_text(o, c),
                  workers > 0 ? fmt::format(" on {} Dask workers ({})", workers, printable(o.scheduler)) : "", seconds);
  out += calibration_failures(sm);
  if (sm.failures > 0)
    out += fmt::format("failures: {} (platform, pose) pairs without an error (refused or forward kinematics failed)\n",
                       sm.failures);
  // After a tracker calibration the errors are micrometres.
  const bool um = tracker_calibration(c);
  const double scale = um ? 1e6 : 1e3;
  const char* length = um ? "um" : "mm";
  out += fmt::format("\n{:<24}{:>30}   {:>20}   {:>14}\n", "", "Monte Carlo", "linearised", "MC / linear");
  out += fmt::format("{:<24}{:>10}{:>10}{:>10}   {:>10}{:>10}   {:>7}{:>7}\n", "error", "median", "p95", "max",
                     "median", "p95", "median", "p95");
  out += row(fmt::format("point A [{}]", length).c_str(), sm.point, sm.point_linear, scale);
  out += row(fmt::format("pivot position [{}]", length).c_str(), sm.position, sm.position_linear, scale);
  out += row(um ? "orientation [urad]" : "orientation [mrad]", sm.orientation, sm.orientation_linear, scale);
  out += fmt::format(
      "worst over the workspace, per platform: point A {:.4f} {} median, {:.4f} {} p95, {:.4f} {} max (the linear "
      "model with the same errors: {:.4f}, {:.4f}, {:.4f} {})\n",
      scale * sm.worst_point.median, length, scale * sm.worst_point.p95, length, scale * sm.worst_point.max, length,
      scale * sm.worst_point_linear.median, scale * sm.worst_point_linear.p95, scale * sm.worst_point_linear.max,
      length);
  out += layouts_text(layouts);
  return out;
}

int run_tolerance(const ToleranceCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  const ToleranceSigmas sigmas = sigmas_of(o);
  check_option(o.platforms >= 1 && o.platforms <= 100'000'000, "--platforms", static_cast<double>(o.platforms),
               "1 to 1e8 platforms");
  OutputFiles set("tolerance");
  set.input("--config", o.model.config);
  for (const std::string& t : o.required.trajectories) set.input("--trajectory", t);
  if (!o.station_plan.empty()) set.input("--station-plan", o.station_plan);
  set.folder("--out", o.out);
  const RequiredPoses req = required_poses(config, o.required);

  // The calibration and the linear model (no sample in it) here; the samples here or on the cluster.
  const CalibrationChoice calibration = calibration_of(o);
  ToleranceOptions to;
  to.sigmas = sigmas;
  to.seed = o.seed;
  to.threads = 0;
  ToleranceLinear linear;
  const Status prepared = prepare_calibration(model, req.poses, calibration, to, linear);  // names its option
  if (prepared == Status::NotIdentifiable)
    throw ExitError(
        kExitBadInput,
        fmt::format("{}: the station plan does not determine the calibrated parameters ({}): plan more "
                    "stations or spread them wider (hexatwist stations)",
                    o.station_plan.empty() ? "--calibration " + o.calibration : "--station-plan " + o.station_plan,
                    describe(prepared)));
  if (prepared != Status::Ok)
    throw ExitError(kExitOutOfLimit,
                    fmt::format("the linear model failed: {} ({})", describe(prepared), to_string(prepared)));
  int workers = 0;
  ToleranceChunk chunk;
  if (!o.scheduler.empty()) {
    chunk = chunk_on_cluster(o, req, sigmas, calibration, workers);
  } else {
    // On a terminal, in parts with a progress line between them (platform k depends on the seed and
    // k alone, so the parts append to the same result bit for bit); else in one call.
    Progress bar(o.platforms, !o.json);
    const std::uint64_t part = bar.drawn() ? std::max<std::uint64_t>(1, o.platforms / kProgressParts) : o.platforms;
    for (std::uint64_t first = 0; first < o.platforms; first += part) {
      const std::uint64_t count = std::min(part, o.platforms - first);
      ToleranceChunk next;
      if (const Status s = tolerance_chunk(model, req.poses, to, first, count, first == 0 ? chunk : next, &linear);
          s != Status::Ok)
        throw ExitError(kExitOutOfLimit, fmt::format("the study failed: {} ({})", describe(s), to_string(s)));
      if (first > 0) append_chunk(chunk, next);
      bar.update(first + count, fmt::format("{} of {} platforms", first + count, o.platforms));
    }
  }
  const ToleranceSummary sm = summarize_tolerance(chunk, req.poses.size(), &linear, 0);
  const std::vector<TargetLayout> layouts =
      o.target_layouts > 0
          ? target_layouts(model, req.poses, to, tracker_calibration_of(model, calibration, o.seed), o.target_layouts)
          : std::vector<TargetLayout>{};
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const fs::path dir(o.out);
  std::vector<std::string> names;
  if (!o.no_csv) names.push_back("platforms.csv");
  std::vector<Figure> figs;
  if (!o.no_figures) {
    figs.push_back(figure((dir / "tolerance").string(), chunk, linear, sm, tracker_calibration(calibration)));
    names.insert(names.end(), {"tolerance.png", "tolerance.svg"});
  }
  names.push_back("summary.json");
  if (!o.no_csv) set.add((dir / "platforms.csv").string(), platforms_csv(chunk));
  const std::string json = summary_json(model, o, req, sigmas, calibration, sm, layouts, workers, seconds, names);
  set.add((dir / "summary.json").string(), json);
  set.stage();
  for (Figure& f : figs) f.stem = set.external(f.stem, {".png", ".svg"});
  if (!figs.empty()) write_figures(figs);
  set.commit();
  std::string text =
      o.json ? json
             : report_text(model, o, req, sigmas, calibration, sm, layouts, workers, seconds, defaults_note(config));
  if (!o.json) text += fmt::format("\n{} written to {}\n", counted(set.paths().size(), "file"), o.out);
  set.finish(text);
  return kExitOk;
}

}  // namespace

Command make_tolerance_command(CLI::App& root) {
  auto o = std::make_shared<ToleranceCommandOptions>();
  CLI::App* app = root.add_subcommand(
      "tolerance",
      "Tolerance analysis (docs/theory/design.md §18): how accurate the platform will be with manufacturing errors, "
      "before it is built. --platforms platforms are sampled, each leg with errors of its joint centres, U-joint axis "
      "directions, lead and zero offset (normal, the standard deviations below), driven over the required workspace "
      "(--workspace SPEC or --trajectory FILE..., as design) by the nominal compensated commands; each pose found "
      "by twist-aware forward kinematics. The Monte Carlo's errors (point A, pivot position, orientation; median, "
      "95th percentile, largest) beside the linearised answer (the covariance of the linear model). Writes to "
      "--out: summary.json (SI), platforms.csv (each platform's worst and RMS errors), tolerance.png/.svg.");
  add_model_options(*app, o->model);
  add_required_options(*app, o->required);
  app->add_option("--platforms", o->platforms, "Platforms sampled")->capture_default_str();
  app->add_option("--seed", o->seed, "Seed of the sampled errors (platform k's errors depend on the seed and k only)")
      ->capture_default_str();
  app->add_option("--sigma-joint-um", o->joint_um, "Joint centres, each coordinate [um]")->capture_default_str();
  app->add_option("--sigma-base-joint-um", o->base_joint_um,
                  "Base joint centres alone [um] (default: --sigma-joint-um)");
  app->add_option("--sigma-platform-joint-um", o->platform_joint_um,
                  "Platform joint centres alone [um] (default: --sigma-joint-um)");
  app->add_option("--sigma-axis-deg", o->axis_deg, "U-joint fixed axis directions, about each normal [deg]")
      ->capture_default_str();
  app->add_option("--sigma-lead-ppm", o->lead_ppm,
                  "Relative lead error [ppm] (ISO 3408 classes over 300 mm as 2 sd: C3 13, C5 30, C7 83)")
      ->capture_default_str();
  app->add_option("--sigma-offset-um", o->offset_um, "Zero offsets, the legs' lengths at the drives' reference [um]")
      ->capture_default_str();
  app->add_option(
         "--calibration", o->calibration,
         "none: the controller runs the nominal configuration; perfect: it runs each real platform's own "
         "(the floor); stations:N[,SEED]: each platform calibrated as identify does (geometry model, a lead "
         "per leg) from a tracker's points at home, N random stations (+-0.25 m, +-15 deg; seed SEED, "
         "default 1: the stations of synth --stations N --station-seed SEED) and home, the controller "
         "running the corrected configuration, the linearised answer from the identification's covariance, errors "
         "reported in um and urad; plan: the stations of --station-plan")
      ->capture_default_str();
  app->add_option("--station-plan", o->station_plan,
                  "A stations run CSV (synth --run-out): each platform calibrated from a tracker's points at the "
                  "poses the run holds (the plan calibration; with --calibration none or plan)");
  app->add_option("--tracker-noise-um", o->tracker_noise_um,
                  "The calibration's tracker: Gaussian noise per coordinate [um]")
      ->capture_default_str();
  app->add_option("--points-per-station", o->points_per_station,
                  "The calibration's tracker: points recorded at each station (the noise from their scatter; 1: "
                  "the identification is told --tracker-noise-um)")
      ->capture_default_str();
  app->add_option("--calibration-frames", o->calibration_frames,
                  "After a tracker calibration, the frames of the errors: tracker (the base as the tracker sees it "
                  "through the identified tracker frame: what a tracker check of the calibrated machine measures) or "
                  "joints (the least-squares frames of the real joints, the identification's gauge)")
      ->check(CLI::IsMember({"tracker", "joints"}))
      ->capture_default_str();
  app->add_option("--targets-mm", o->targets_mm,
                  "The calibration's tracker: more targets on the platform besides point A, measured at every "
                  "station, \"x,y,z;x,y,z\" [mm, platform frame] (synth's option): with them the pivot and the "
                  "orientation calibrate as point A does");
  app->add_option("--target-layouts", o->target_layouts,
                  "Also compare layouts of 1 to 1+N targets (point A and N more evenly on the circle through it about "
                  "the pivot) calibrated from the same stations: the linearised point A, pivot and orientation errors "
                  "of each, to choose where to put the targets; 0 = none")
      ->check(CLI::Range(0, kMaxLayoutTargets))
      ->capture_default_str();
  app->add_option("--out", o->out, "Output folder (created if missing), written as a set: all files or none (exit 4)")
      ->capture_default_str();
  app->add_flag("--json", o->json, "Print summary.json instead of the text report");
  app->add_flag("--no-figures", o->no_figures, "Skip the figure (gnuplot)");
  app->add_flag("--no-csv", o->no_csv, "Skip platforms.csv");
  add_scheduler_option(*app, o->scheduler);
  return {app, [o, app] {
            // The tracker's options have an effect only on a tracker calibration: refused, not ignored, without one.
            const bool tracker = is_tracker_calibration(o->calibration) || !o->station_plan.empty();
            for (const char* option : {"--tracker-noise-um", "--points-per-station", "--calibration-frames",
                                       "--targets-mm", "--target-layouts"})
              if (!tracker && app->count(option) > 0)
                throw ExitError(kExitBadInput,
                                fmt::format("{}: only with a tracker calibration (--calibration "
                                            "stations:N[,SEED], or --station-plan), not with --calibration {}",
                                            option, o->calibration));
            return run_tolerance(*o);
          }};
}

}  // namespace hexatwist::cli
