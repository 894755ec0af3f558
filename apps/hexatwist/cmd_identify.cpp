// SPDX-License-Identifier: BSD-3-Clause
// hexatwist identify: the platform identified from a tracker's point log (the library decides,
// identification.hpp), printed, and written as a corrected configuration with the map of its
// predicted accuracy (docs/theory/calibration.md §13).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "cli_common.hpp"
#include "figures.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "run_options.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct IdentifyOptions {
  RunOptions run;
  LogOptions log;
  double settle = 0.25;
  std::string model = "geometry";
  std::string lead_effect = "travel";
  std::string axes = "auto";
  std::string effects = "auto";
  double tracker_noise_um = std::numeric_limits<double>::quiet_NaN();
  int folds = 5;
  std::string out = "identified.yaml";
  bool no_figures = false;
  bool json = false;
};

IdentificationOptions library_options(const IdentifyOptions& o) {
  IdentificationOptions io;
  io.model = o.model == "basic" ? CalibrationModel::Basic : CalibrationModel::Geometry;
  io.lead_effect = o.lead_effect == "twist" ? LeadEffect::TwistOnly : LeadEffect::TwistAndTravel;
  io.axes = o.axes == "none" ? AxisFit::None : o.axes == "all" ? AxisFit::All : AxisFit::Auto;
  io.auto_effects = o.effects == "auto";
  if (!io.auto_effects) io.effects = effect_fit(o.effects);
  io.tracker_noise = o.tracker_noise_um * 1e-6;
  io.folds = o.folds;
  return io;
}

// Everything identify reports, gathered once for the text and the JSON.
struct Report {
  const IdentifyOptions& o;
  const Model& nominal;
  const ObservationSet& set;
  const PointLog& log;
  const Identification& id;
  std::string run_description;
  ClockFit clock;
  std::size_t outside = 0;  // points of the log outside the run (--time-offset auto)
  std::string defaults;     // defaults_note of the configuration

  int line_of(std::size_t observation) const { return log.lines[set.points[observation]]; }
  const ParameterSet& ps() const { return id.parameters; }
};

const char* model_name(CalibrationModel m) { return m == CalibrationModel::Basic ? "basic" : "geometry"; }

std::string status_word(Status s) {
  switch (s) {
    case Status::NotIdentifiable:
      return "not identifiable";
    case Status::SolverNoConvergence:
      return "no convergence";
    case Status::SignUndecided:
      return "thread sense not decided";
    case Status::ModelMismatch:
      return "the model does not explain the data";
    default:
      return "failed";
  }
}

// The parameter table: every platform parameter in display units, joints per coordinate.
struct Row {
  std::string name, unit;
  double nominal, estimate, sd;
  int decimals;
};

std::vector<Row> parameter_rows(const Report& r) {
  const Identification& id = r.id;
  const ParameterSet& ps = r.ps();
  std::vector<Row> rows;
  for (int j = 0; j < ps.lead_count(); ++j)
    rows.push_back({ps.name(j), "mm", 1e3 * id.nominal[j], 1e3 * id.estimate[j], 1e3 * id.sd[j], 6});
  for (int i = 0; i < kLegs; ++i) {
    const int k = ps.offset_index() + i;
    rows.push_back({ps.name(k), "mm", 1e3 * id.nominal[k], 1e3 * id.estimate[k], 1e3 * id.sd[k], 4});
  }
  if (ps.model() == CalibrationModel::Geometry) {
    const ModelSpec& n = ps.nominal();
    for (int i = 0; i < kLegs; ++i)
      for (int a = 0; a < 3; ++a)
        rows.push_back(
            {fmt::format("base {} {}", i + 1, "xyz"[a]), "mm", 1e3 * n.legs[static_cast<std::size_t>(i)].base_B[a],
             1e3 * id.corrected.legs[static_cast<std::size_t>(i)].base_B[a], 1e3 * id.base_shift_sd(i, a), 4});
    for (int i = 0; i < kLegs; ++i)
      for (int a = 0; a < 3; ++a)
        rows.push_back({fmt::format("platform {} {}", i + 1, "xyz"[a]), "mm",
                        1e3 * n.legs[static_cast<std::size_t>(i)].platform_P[a],
                        1e3 * id.corrected.legs[static_cast<std::size_t>(i)].platform_P[a],
                        1e3 * id.platform_shift_sd(i, a), 4});
    for (int k = ps.axis_index(); k < ps.axis_index() + ps.axis_count(); ++k)
      rows.push_back({ps.name(k), "deg", 0.0, rad2deg(id.estimate[k]), rad2deg(id.sd[k]), 4});
  }
  if (ps.compliance_index() >= 0) {
    const int k = ps.compliance_index();
    rows.push_back({ps.name(k), "um/kN", 1e9 * id.nominal[k], 1e9 * id.estimate[k], 1e9 * id.sd[k], 4});
  }
  const int effects_end = ps.effect_index() + ps.effects().count();
  const bool measured = ps.effects().measured;  // heat per kelvin, from the log's temperatures
  for (int k = ps.effect_index(); k < effects_end; ++k)
    if (k == ps.lead_drift_index())
      rows.push_back({ps.name(k), measured ? "ppm/K" : "ppm", 0.0, 1e6 * id.estimate[k], 1e6 * id.sd[k], 2});
    else if (measured && k >= ps.drift_index() && k < ps.drift_index() + kLegs)
      rows.push_back({ps.name(k), "um/K", 0.0, 1e6 * id.estimate[k], 1e6 * id.sd[k], 3});
    else if (k != ps.compliance_index())
      rows.push_back({ps.name(k), "mm", 1e3 * id.nominal[k], 1e3 * id.estimate[k], 1e3 * id.sd[k], 4});
  for (int k = ps.target_index(); k < ps.rotation_index(); ++k)
    rows.push_back({k - ps.target_index() < 3 ? fmt::format("point {}", "xyz"[k - ps.target_index()]) : ps.name(k),
                    "mm", 1e3 * id.nominal[k], 1e3 * id.estimate[k], 1e3 * id.sd[k], 4});
  return rows;
}

// Which axes were fitted, and how well the data determine them, in one phrase. An axis whose
// standard deviation exceeds 10 deg is undetermined (1e2-1e5 deg is no estimate at all).
std::string axes_phrase(const Identification& id) {
  if (id.parameters.model() != CalibrationModel::Geometry) return "joints as configured";
  const int fitted = id.parameters.axis_count() / 2;
  constexpr double kUndetermined = deg2rad(10.0);
  double lo = INFINITY, hi = 0.0;
  int undetermined = 0, total = 0;
  for (const double sd : id.axis_sd) {
    if (std::isnan(sd)) continue;
    ++total;
    if (!(sd <= kUndetermined)) {
      ++undetermined;
      continue;
    }
    lo = std::min(lo, sd), hi = std::max(hi, sd);
  }
  std::string sds;
  if (std::isfinite(lo)) sds = fmt::format("the data determine them to {:.2g}-{:.2g} deg", rad2deg(lo), rad2deg(hi));
  if (undetermined > 0)
    sds += fmt::format("{}{} undetermined (sd above 10 deg)", sds.empty() ? "" : "; ",
                       undetermined == total ? std::string("all") : fmt::format("{} of {}", undetermined, total));
  if (fitted == 0)
    return sds.empty() ? "U-joint axes as configured" : fmt::format("U-joint axes as configured ({}: not fitted)", sds);
  return fmt::format("{} U-joint ax{} fitted{}", fitted, fitted == 1 ? "is" : "es",
                     sds.empty() ? "" : " (" + sds + ")");
}

std::string text_report(const Report& r) {
  const Identification& id = r.id;
  const IdentifyOptions& o = r.o;
  std::string t =
      fmt::format("hexatwist identify on {}: {}{}\n", model_source(o.run.model), r.nominal.spec().name, r.defaults);
  t += fmt::format(
      "points: {}: {} points, {} at rest (commanded pose still for {:g} s) at {} stations, {} target{}; {}; {} "
      "commands\n",
      printable(o.log.points), r.log.points_T.size(), id.observations, r.set.settle, id.stations, r.set.targets.size(),
      r.set.targets.size() == 1 ? "" : "s", r.run_description, o.run.strategy);
  t += clock_line(r.clock, o.log, r.outside);
  t += fmt::format("model: {} ({}), lead effect {}\n", model_name(r.ps().model()), axes_phrase(id),
                   r.ps().lead_effect() == LeadEffect::TwistAndTravel
                       ? "travel (the drives turn the screws by the nominal lead's angles)"
                       : "twist only (the drives' travel is right)");
  if (r.ps().effects().any() || !id.effects_choice.empty())
    t += fmt::format("legs' effects: {}\n", id.effects_choice.empty() ? r.ps().effects().names() : id.effects_choice);
  const SignFit& plus = id.fits[0];
  const SignFit& minus = id.fits[1];
  t += fmt::format("thread sense: as configured cost {:.4g} m^2{}, flipped cost {:.4g} m^2{}: {}, cost ratio {:.3g}\n",
                   plus.cost, plus.lead_at_bound ? " (lead at 0)" : "", minus.cost,
                   minus.lead_at_bound ? " (lead at 0)" : "",
                   id.twist_sign > 0 ? "as configured" : "flipped (every leg the other hand)", id.cost_ratio);
  t += fmt::format(
      "fit: rms {:.4f} mm before (nominal model, tracker frame by Kabsch), {:.4f} mm after, largest {:.4f} mm (line "
      "{}); noise {:.4f} mm per axis, the tracker's {:.4f} mm: test {:.2f} sigma (at most 5), unexplained {:.4f} mm "
      "per axis; condition {:.3g}\n",
      1e3 * id.rms_before, 1e3 * id.rms_after, 1e3 * id.max_after,
      r.line_of(static_cast<std::size_t>(id.max_after_index)), 1e3 * id.sigma, 1e3 * id.tracker_noise, id.fit_z,
      1e3 * id.unexplained, id.condition);
  const CrossValidation& cv = id.cross_validation;
  if (cv.folds > 0 && cv.predicted == 0)
    t += fmt::format(
        "cross-validated ({} folds over the stations): not possible: with a fold's stations left out the "
        "rest do not determine the model (too few stations: plan more)\n",
        cv.folds);
  else if (cv.folds > 0)
    t += fmt::format(
        "cross-validated ({} folds over the stations): the {} left-out stations' mean points are predicted to {:.1f} "
        "um rms, {:.1f} um at most ({:.1f} um expected from the noise and the covariance)\n",
        cv.folds, cv.predicted, 1e6 * cv.rms, 1e6 * cv.max, 1e6 * cv.expected);
  const AccuracyPrediction& acc = id.accuracy;
  t += fmt::format(
      "predicted accuracy of point A over the calibrated range ({} poses within {:.3f}..{:.3f} m, {:.1f}..{:.1f} deg): "
      "median {:.4f} mm, largest {:.4f} mm in the gauge frames; {:.4f} mm and {:.4f} mm after a rigid re-alignment\n",
      acc.poses, acc.range_low.head<3>().minCoeff(), acc.range_high.head<3>().maxCoeff(),
      rad2deg(acc.range_low.tail<3>().minCoeff()), rad2deg(acc.range_high.tail<3>().maxCoeff()), 1e3 * acc.median,
      1e3 * acc.max, 1e3 * acc.aligned_median, 1e3 * acc.aligned_max);
  t += fmt::format("{:<18} {:>12} {:>12} {:>10} {:>12}\n", "parameter", "nominal", "estimate", "sd", "change");
  for (const Row& row : parameter_rows(r)) {
    const std::string change = row.name.starts_with("lead") && row.nominal != 0.0
                                   ? fmt::format("{:+.4f} %", 100.0 * (row.estimate / row.nominal - 1.0))
                                   : fmt::format("{:+.{}f}", row.estimate - row.nominal, row.decimals);
    t += fmt::format("{:<18} {:>12.{}f} {:>12.{}f} {:>10.{}f} {:>12}  [{}]\n", row.name, row.nominal, row.decimals,
                     row.estimate, row.decimals, row.sd, row.decimals, change, row.unit);
  }
  const Eigen::AngleAxisd turn(id.X_BT.R);
  t += fmt::format(
      "tracker frame in the base frame: origin ({:.4f}, {:.4f}, {:.4f}) m, turned {:.4f} deg about ({:.4f}, {:.4f}, "
      "{:.4f})\n",
      id.X_BT.t.x(), id.X_BT.t.y(), id.X_BT.t.z(), rad2deg(turn.angle()), turn.axis().x(), turn.axis().y(),
      turn.axis().z());
  if (r.ps().model() == CalibrationModel::Geometry)
    t += "gauge: B is the least-squares frame of the six base joint centres, P that of the six platform joint centres "
         "(the joint displacements have no rigid part)\n";
  return t;
}

// The fit, its tests and the solves of both thread senses.
void json_fit(JsonWriter& j, const Report& r) {
  const Identification& id = r.id;
  j.number_or_null("rms_before", id.rms_before, true);
  j.number_or_null("rms_after", id.rms_after, id.fitted);
  j.number_or_null("max_after", id.max_after, id.fitted);
  j.key("max_after_line");
  id.fitted&& id.max_after_index >= 0 ? j.value(r.line_of(static_cast<std::size_t>(id.max_after_index))) : j.null();
  j.number_or_null("sigma", id.sigma, id.fitted);
  j.number_or_null("tracker_noise", id.tracker_noise, true);
  j.number_or_null("scatter", id.scatter, true);
  j.number_or_null("noise_ratio", id.sigma / id.tracker_noise, id.fitted);
  j.number_or_null("unexplained", id.unexplained, id.fitted);
  j.key("diagnosis").begin_array(true);
  for (const Identification::EffectDiagnosis& d : id.diagnosis) {
    j.begin_object().field("effect", d.effect);
    j.number_or_null("z", d.z, true);
    j.end_object();
  }
  j.end_array();
  j.key("fit_test").begin_object();
  j.number_or_null("statistic", id.fit_statistic, id.fitted);
  j.field("dof", id.fit_dof);
  j.number_or_null("z", id.fit_z, id.fitted);
  j.field("limit", library_options(r.o).fit_sigmas).end_object();
  j.key("worst_stations").begin_array(true);
  for (const StationResidual& w : id.worst) {
    j.begin_object().field("station", w.station + 1).field("target", r.set.targets[static_cast<std::size_t>(w.target)]);
    j.field("line", r.line_of(w.first)).field("points", w.count).field("mean_error", w.mean_error);
    j.field("statistic", w.statistic).end_object();
  }
  j.end_array();
  j.number_or_null("condition", id.condition, true);
  if (!id.undetermined.empty()) j.field("undetermined", id.undetermined);
  j.number_or_null("cost_ratio", id.cost_ratio, id.fitted);
  j.number_or_null("sign_separation", id.sign_separation, id.fitted);
  j.key("fits").begin_array(true);
  for (const SignFit& f : id.fits) {
    j.begin_object().field("twist_sign", f.twist_sign).field("status", describe(f.status));
    j.number_or_null("cost", f.cost, std::isfinite(f.cost));
    j.field("iterations", f.iterations).field("lead_at_bound", f.lead_at_bound).end_object();
  }
  j.end_array();
}

// The axes, the cross-validation and the predicted accuracy.
void json_diagnostics(JsonWriter& j, const Identification& id) {
  j.key("axis_sd").begin_array();
  for (const double sd : id.axis_sd) std::isfinite(sd) ? j.value(sd) : j.null();
  j.end_array();
  j.key("axes_fitted").begin_array();
  for (const bool a : id.parameters.axes()) j.value(a);
  j.end_array();
  const CrossValidation& cv = id.cross_validation;
  j.key("cross_validation").begin_object().field("folds", cv.folds).field("predicted", cv.predicted);
  j.number_or_null("rms", cv.rms, cv.folds > 0);
  j.number_or_null("max", cv.max, cv.folds > 0);
  j.number_or_null("expected", cv.expected, cv.folds > 0);
  j.end_object();
  const AccuracyPrediction& acc = id.accuracy;
  j.key("accuracy").begin_object().field("poses", acc.poses);
  j.number_or_null("median", acc.median, acc.poses > 0);
  j.number_or_null("max", acc.max, acc.poses > 0);
  j.number_or_null("aligned_median", acc.aligned_median, acc.poses > 0);
  j.number_or_null("aligned_max", acc.aligned_max, acc.poses > 0);
  j.key("range_low").vector(acc.range_low);
  j.key("range_high").vector(acc.range_high);
  j.end_object();
}

// The estimate: every parameter with its sd, and the corrected platform's quantities.
void json_estimate(JsonWriter& j, const Identification& id) {
  const ParameterSet& ps = id.parameters;
  j.begin_object();
  j.key("parameters").begin_array(true);
  for (int k = 0; k < ps.size(); ++k)
    j.begin_object()
        .field("name", ps.name(k))
        .field("nominal", id.nominal[k])
        .field("estimate", id.estimate[k])
        .field("sd", id.sd[k])
        .end_object();
  j.end_array();
  j.field("twist_sign", id.twist_sign);
  const ModelSpec& c = id.corrected;
  const auto per_leg = [&](std::string_view key, auto&& value) {
    j.key(key).begin_array();
    for (int i = 0; i < kLegs; ++i) value(i);
    j.end_array();
  };
  const auto leg = [&](int i) -> const LegSpec& { return c.legs[static_cast<std::size_t>(i)]; };
  per_leg("leads", [&](int i) { j.value(leg(i).lead); });
  per_leg("threads", [&](int i) { j.value(leg(i).thread == ThreadSense::Right ? "right" : "left"); });
  per_leg("length_offsets", [&](int i) { j.value(leg(i).length_offset); });
  per_leg("base_joints", [&](int i) { j.vector(leg(i).base_B); });
  per_leg("base_joints_sd", [&](int i) { j.vector(Vector3d(id.base_shift_sd.row(i).transpose())); });
  per_leg("platform_joints", [&](int i) { j.vector(leg(i).platform_P); });
  per_leg("platform_joints_sd", [&](int i) { j.vector(Vector3d(id.platform_shift_sd.row(i).transpose())); });
  j.key("targets").begin_array();
  for (int t = 0; t < ps.targets(); ++t) j.vector(ps.target(id.estimate, t));
  j.end_array();
  j.key("observation_point").vector(c.observation_P);
  j.key("X_BT").begin_object();
  j.key("R").begin_array();
  for (int i = 0; i < 3; ++i) j.vector(id.X_BT.R.row(i));
  j.end_array();
  j.key("t").vector(id.X_BT.t);
  j.key("rotation_sd").vector(id.sd.segment<3>(ps.rotation_index()));
  j.key("t_sd").vector(id.sd.segment<3>(ps.translation_index()));
  j.end_object().end_object();
}

std::string json_report(const Report& r, const std::string& failure, bool written) {
  const Identification& id = r.id;
  JsonWriter j;
  j.begin_document(schema::kIdentify).field("command", "identify").field("status", failure.empty() ? "ok" : "failed");
  j.field("identification", to_string(id.status));
  // The log's clock against the run's: as given (--time-offset SECONDS), or found from the rests.
  const ClockFit& c = r.clock;
  j.key("clock").begin_object().field("found", c.matched > 0).field("offset", c.offset).field("scale", c.scale);
  j.field("offset_sd", c.offset_sd).field("scale_sd", c.scale_sd).field("worst", c.worst);
  j.field("matched", c.matched).end_object();
  if (!failure.empty()) j.field("reason", failure);
  if (!id.hint.empty()) j.field("hint", id.hint);
  j.field("model", r.nominal.spec().name).field("config", model_source(r.o.run.model)).field("points", r.o.log.points);
  j.field("calibration_model", model_name(r.ps().model())).field("lead_effect", r.o.lead_effect);
  j.field("effects", r.ps().effects().names()).field("effects_choice", id.effects_choice);
  j.field("log_points", static_cast<int>(r.log.points_T.size())).field("observations", id.observations);
  j.field("stations", id.stations).field("groups", id.groups).field("settle", r.set.settle);
  j.field("strategy", r.o.run.strategy);
  j.key("targets").begin_array();
  for (const std::string& name : r.set.targets) j.value(name);
  j.end_array();
  json_fit(j, r);
  json_diagnostics(j, id);
  j.key("estimate");
  if (id.status == Status::Ok)
    json_estimate(j, id);
  else
    j.null();
  j.key("corrected_config");
  written ? j.value(r.o.out) : j.null();
  j.end_object();
  return j.str();
}

// The map of the predicted accuracy at the calibrated range's centre: the x-y plane at its middle
// height and the x-z plane at its middle y, each a continuous colour scale of its own (so that the
// small differences of the x-y plane show), with the re-aligned figures and the frames in plain words.
Figure accuracy_figure(const Identification& id, const std::string& stem) {
  Figure fig;
  fig.stem = stem;
  const AccuracyPrediction& acc = id.accuracy;
  fig.title = "predicted error of point A after calibration, no rotation (blank: outside a limit)";
  // What the frames mean, and the figures after re-alignment, in the panels' titles (one line each,
  // at most about 125 characters: the figure's width).
  const std::array<std::string, 2> notes{
      "in frames fitted to the six joints: a rigid shift of the machine not counted",
      fmt::format("after a rigid re-alignment to the tracker: median {:.1f} um, largest {:.1f} um",
                  1e6 * acc.aligned_median, 1e6 * acc.aligned_max)};
  const Eigen::MatrixXd C = id.covariance.topLeftCorner(id.parameters.platform_size(), id.parameters.platform_size());
  const std::array<std::pair<int, int>, 2> planes{{{0, 1}, {0, 2}}};
  for (const auto& [a, b] : planes) {
    AccuracyMap map;
    if (accuracy_map(id.parameters, id.estimate, id.twist_sign, C, acc, a, b, 41, map) != Status::Ok) continue;
    if (std::none_of(map.error.begin(), map.error.end(), [](double e) { return std::isfinite(e); })) continue;
    const int c = 3 - a - b;
    Panel panel(fmt::format("{}-{} plane at {} = {:.3f} m (the range's centre); {}", "xyz"[a], "xyz"[b], "xyz"[c],
                            0.5 * (acc.range_low[c] + acc.range_high[c]), notes[fig.panels.size()]),
                fmt::format("{} [m]", "xyz"[a]), fmt::format("{} [m]", "xyz"[b]));
    HeatMap heat;
    heat.u = map.u;
    heat.v = map.v;
    heat.label = "predicted error of point A [um]";
    for (const double e : map.error) heat.values.push_back(1e6 * e);
    panel.map = std::move(heat);
    panel.equal_axes = true;
    fig.panels.push_back(std::move(panel));
  }
  return fig;
}

// The corrected configuration: the user's file (or the seed) with the identified platform in the
// legs form, and the drives' reference recorded (the contract of theory §4). Throws Error if it
// does not load.
std::string corrected_config(const IdentifyOptions& o, const Model& model, const Identification& id) {
  const std::string source_text = o.run.model.config.empty()
                                      ? std::string(seed_config_yaml())
                                      : read_text_file(o.run.model.config, "--config", "config file");
  ModelSpec corrected = id.corrected;
  // The name says what was identified, so that a number in the original name (a nominal lead)
  // is not taken for the identified one.
  double lead_min = corrected.legs[0].lead, lead_max = lead_min;
  for (const LegSpec& leg : corrected.legs) {
    lead_min = std::min(lead_min, leg.lead);
    lead_max = std::max(lead_max, leg.lead);
  }
  const std::string leads = lead_max - lead_min < 5e-10
                                ? fmt::format("lead {:.6g} mm", 1e3 * lead_min)
                                : fmt::format("leads {:.6g} to {:.6g} mm", 1e3 * lead_min, 1e3 * lead_max);
  corrected.name = fmt::format("{} (identified from {}: {}; the identified values below replace the name's)",
                               model.spec().name, o.log.points, leads);
  const std::string header = fmt::format(
      "corrected by hexatwist identify ({} model) from {} ({} points at rest at {} stations, rms {:.4f} -> {:.4f} "
      "mm):\njoint centres, leads, thread hands, length_offsets and observation_point identified; home_commands and\n"
      "drive_lead record the drives' reference and scale the log was recorded with (keep the controller's HOME and "
      "scale);\nB and P are the least-squares frames of the base and platform joint centres; everything else as in "
      "{}.",
      model_name(id.parameters.model()), o.log.points, id.observations, id.stations, 1e3 * id.rms_before,
      1e3 * id.rms_after, model_source(o.run.model));
  return platform_config_yaml(source_text, model_source(o.run.model), corrected, header, true);
}

int run_identify(const IdentifyOptions& o) {
  // Inputs and outputs first: an output that is an input is refused before any work.
  OutputFiles files("identify");
  files.input("--config", o.run.model.config);
  files.input("--trajectory", o.run.trajectory);
  files.input("--points", o.log.points);
  files.output("--out", o.out);
  const std::filesystem::path out_path(o.out);
  const std::string figure_stem = (out_path.parent_path() / (out_path.stem().string() + "_accuracy")).string();
  if (!o.no_figures) {
    files.output("the accuracy map beside --out", figure_stem + ".png");
    files.output("the accuracy map beside --out", figure_stem + ".svg");
  }
  const Config config = load_config_from(o.run.model);
  const Model& model = config.rig.model();
  const PointLogFormat format = log_format(o.log);
  check_option(o.settle >= 0.0, "--settle", o.settle, "a time >= 0 [s]");
  check_identification_options(library_options(o));  // before the log is read: exit 2 naming the option
  const Run run = build_run(config, o.run);
  check_option(o.settle < run.test.trajectory.duration(), "--settle", o.settle,
               fmt::format("a time shorter than the run ({:g} s): no point can be still for longer [s]",
                           run.test.trajectory.duration()));
  PointLog log = read_point_log(o.log, format);
  ClockFit clock;
  std::size_t outside = 0;
  const TimeAlignment alignment = log_alignment(o.log, run, log, clock, outside);
  // Bad input throws (exit 2, naming the option at fault).
  const ObservationSet set = observations_at_rest(model, run.commanded, log, alignment, strategy_of(o.run), o.settle);
  Identification id;
  const Status status = identify(model, set.observations, id, library_options(o));
  const Report report{o, model, set, log, id, run.test.description, clock, outside, defaults_note(config)};
  // A failure still prints the JSON (with the reason, and null where there is no value) when asked.
  const auto fail = [&](const ExitError& e) {
    if (o.json) write_stdout(json_report(report, e.what(), false));
    throw e;
  };
  // A log that is not of this run is bad input, refused as measure refuses it (exit 2).
  if (status == Status::InvalidArgument)
    fail(ExitError(kExitBadInput, fmt::format("{}: {}; nothing was written", printable(o.log.points), id.reason)));
  if (status != Status::Ok)
    fail(ExitError(kExitNotIdentified,
                   fmt::format("{}: {} points at rest at {} station{}: {}: {}{}; nothing was written",
                               printable(o.log.points), set.observations.size(), set.poses, set.poses == 1 ? "" : "s",
                               status_word(status), id.reason, id.hint.empty() ? "" : "; hint: " + id.hint)));

  std::string yaml;
  try {
    yaml = corrected_config(o, model, id);
  } catch (const Error& e) {
    fail(ExitError(kExitNotIdentified,
                   fmt::format("{}: the corrected configuration does not load: {}; nothing was written",
                               printable(o.out), e.what())));
  }
  files.add(o.out, yaml);
  if (!o.no_figures) {
    Figure figure = accuracy_figure(id, figure_stem);
    figure.stem = files.external(figure_stem, {".png", ".svg"});
    try {
      write_figures({figure});
    } catch (const ExitError& e) {
      fail(e);
    }
  }
  try {
    files.commit();
  } catch (const ExitError& e) {
    fail(e);
  }
  std::string text = o.json ? json_report(report, std::string(), true) : text_report(report);
  if (!o.json)
    text += fmt::format(
        "wrote {}: the corrected configuration (legs form){}\n", o.out,
        o.no_figures ? "" : fmt::format(", and the map of its predicted accuracy {}.png/.svg", figure_stem));
  files.finish(text);
  return kExitOk;
}

}  // namespace

Command make_identify_command(CLI::App& root) {
  auto o = std::make_shared<IdentifyOptions>();
  CLI::App* app = root.add_subcommand(
      "identify",
      "Calibrates the platform from a laser tracker's point log of one or more targets on it, taken at stations "
      "where it stood still: by nonlinear least squares (Ceres), twist-aware, the twelve U-joint centres, the "
      "screw lead(s), the thread sense, each leg's zero offset, the targets and the tracker frame (--model geometry; "
      "--model basic keeps the joints as configured). The library decides: every parameter determined, the fit as "
      "good as the tracker's noise (an F test at 5 sigma), the thread sense decided; it reports standard deviations, "
      "a cross-validation over the stations and the accuracy it predicts, and writes the corrected configuration "
      "(legs form) with a map of that accuracy. Exit 5 when the data do not determine the parameters, the model does "
      "not explain them, the thread sense is not decided or the solver does not converge; exit 4 if a file cannot "
      "be written. --json is printed on failure too, its status agreeing with the exit code.");
  add_log_options(*app, o->log);
  add_run_options(*app, o->run);
  app->add_option("--settle", o->settle,
                  "Use the points whose commanded pose has been still for this long [s]; 0 = every point (the servo "
                  "lags in motion)")
      ->capture_default_str();
  app->add_option("--model", o->model,
                  "geometry: the joint centres too (the default); basic: lead, thread sense, offsets, targets and "
                  "tracker frame on the configured joints")
      ->check(CLI::IsMember({"geometry", "basic"}))
      ->capture_default_str();
  app->add_option("--lead-effect", o->lead_effect,
                  "travel: the drives turn the screws by the nominal lead's angles, so a wrong lead also scales the "
                  "travel; twist: only the twist term sees it (the drives' travel is right)")
      ->check(CLI::IsMember({"travel", "twist"}))
      ->capture_default_str();
  app->add_option("--axes", o->axes,
                  "U-joint fixed axes (geometry model): auto fits those the data determine to 0.1 deg, none keeps "
                  "them as configured, all fits every one")
      ->check(CLI::IsMember({"auto", "none", "all"}))
      ->capture_default_str();
  app->add_option("--effects", o->effects,
                  "The legs' effects fitted besides the geometry, comma-separated: load (one compliance under the "
                  "configuration's load), play (each leg's, from approaches from both sides), heat (each leg's drift "
                  "over the run and its curvature, and the screws' lead drift; with the log's temperature column, each "
                  "leg's expansion per "
                  "kelvin and the lead's, kept in the corrected configuration); none; auto: those the data show "
                  "(each at 5 sigma)")
      ->check([](const std::string& v) {
        if (v == "auto") return std::string();
        try {
          (void)effect_fit(v);
          return std::string();
        } catch (const Error& e) {
          return std::string(e.what());
        }
      })
      ->capture_default_str();
  app->add_option("--tracker-noise-um", o->tracker_noise_um,
                  "The tracker's noise per axis [um], for logs without repeated points at rest (default: their "
                  "scatter at rest)");
  app->add_option("--folds", o->folds, "Cross-validation folds over the stations; 0 = none")->capture_default_str();
  app->add_option("--out", o->out,
                  "The corrected configuration to write (YAML); its accuracy map goes beside it as "
                  "<stem>_accuracy.png/.svg")
      ->capture_default_str();
  app->add_flag("--no-figures", o->no_figures, "Skip the accuracy map (gnuplot)");
  app->add_flag("--json", o->json, "Machine-readable output (SI units: m, rad)");
  return {app, [o] { return run_identify(*o); }};
}

}  // namespace hexatwist::cli
