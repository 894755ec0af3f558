// SPDX-License-Identifier: BSD-3-Clause
// hexatwist compare: what changed between two configurations' platforms, joint by joint, and where
// the first one's commands put point A on the second (calibration/validation.hpp).
#include <fmt/format.h>

#include <memory>

#include "cli_common.hpp"
#include "json.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct CompareOptions {
  std::string a, b;
  int stations = 60;
  std::uint64_t station_seed = 1;
  std::string range = "0.25,15";
  bool json = false;
};

// "+0.0123" mm from metres, rounding-level values as 0.
std::string mm(double m) { return fmt::format("{:+.4f}", 1e3 * tidy(m)); }

std::string text_report(const CompareOptions& o, const Model& a, const PlatformDifference& d, const StationsSpec& run,
                        const CommandAccuracy& acc) {
  std::string s = fmt::format("hexatwist compare: B {} against A {} (B - A)\n", printable(o.b), printable(o.a));
  s += fmt::format("{:<12} {:>32}   {:>32} {:>10}\n", "joint", "A: x, y, z [mm]", "B - A: x, y, z [mm]", "|B - A|");
  for (const bool platform : {false, true})
    for (int i = 0; i < kLegs; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Vector3d& at = platform ? a.spec().legs[k].platform_P : a.spec().legs[k].base_B;
      const Vector3d& dv = platform ? d.legs[k].platform : d.legs[k].base;
      s += fmt::format("{:<12} {:>10.4f} {:>10.4f} {:>10.4f}   {:>10} {:>10} {:>10} {:>10.4f}\n",
                       fmt::format("{} {}", platform ? "platform" : "base", i + 1), 1e3 * at.x(), 1e3 * at.y(),
                       1e3 * at.z(), mm(dv.x()), mm(dv.y()), mm(dv.z()), 1e3 * dv.norm());
    }
  s += "B - A per leg: lead, the drive's lead, zero offset and home command [mm], the fixed axes' angles [deg], play\n"
       "[um] and compliance [um/kN]\n";
  s += fmt::format("{:<4} {:>11} {:>11} {:>11} {:>13} {:>11} {:>15} {:>10} {:>14}\n", "leg", "lead", "drive lead",
                   "offset", "home command", "base axis", "platform axis", "play", "compliance");
  for (int i = 0; i < kLegs; ++i) {
    const LegDifference& l = d.legs[static_cast<std::size_t>(i)];
    s += fmt::format("{:<4} {:>+11.6f} {:>+11.6f} {:>11} {:>13} {:>11.4f} {:>15.4f} {:>+10.2f} {:>+14.4f}{}\n", i + 1,
                     1e3 * tidy(l.lead), 1e3 * tidy(l.drive_lead), mm(l.length_offset), mm(l.home_command),
                     rad2deg(l.base_axis), rad2deg(l.platform_axis), 1e6 * tidy(l.play), 1e9 * tidy(l.compliance),
                     l.thread_differs ? "  thread hands differ" : "");
  }
  s += fmt::format("point A: [{}, {}, {}] mm; home height {} mm\n", mm(d.observation.x()), mm(d.observation.y()),
                   mm(d.observation.z()), mm(d.home_height));
  s += fmt::format("largest joint difference: {} {}, {:.4f} mm\n", d.largest_on_platform ? "platform" : "base",
                   d.largest_joint_leg + 1, 1e3 * d.largest_joint);
  // Micrometres, or millimetres from 1 mm on.
  const auto length = [](double m) {
    return m < 1e-3 ? fmt::format("{:.1f} um", 1e6 * m) : fmt::format("{:.3f} mm", 1e3 * m);
  };
  s += fmt::format(
      "A's compensated commands on B at {} stations (seed {}, within ±{:g} m and ±{:g} deg): point A off by {} "
      "median, {} at most in the gauge frames; {} and {} after a rigid re-alignment\n",
      acc.gauge.size(), run.seed, run.translation, rad2deg(run.rotation), length(acc.gauge_median),
      length(acc.gauge_max), length(acc.aligned_median), length(acc.aligned_max));
  return s;
}

std::string json_report(const CompareOptions& o, const PlatformDifference& d, const StationsSpec& run,
                        const CommandAccuracy& acc) {
  JsonWriter j;
  j.begin_document(schema::kCompare).field("a", o.a).field("b", o.b);
  j.key("legs").begin_array(true);
  for (const LegDifference& l : d.legs) {
    j.begin_object();
    j.key("base").vector(l.base);
    j.key("platform").vector(l.platform);
    j.field("base_axis_angle", l.base_axis)
        .field("platform_axis_angle", l.platform_axis)
        .field("lead", l.lead)
        .field("drive_lead", l.drive_lead)
        .field("length_offset", l.length_offset)
        .field("home_command", l.home_command)
        .field("compliance", l.compliance)
        .field("play", l.play)
        .field("thread_differs", l.thread_differs)
        .end_object();
  }
  j.end_array();
  j.key("observation_point").vector(d.observation);
  j.field("home_height", d.home_height)
      .field("largest_joint", d.largest_joint)
      .field("largest_joint_leg", d.largest_joint_leg + 1)
      .field("largest_joint_side", d.largest_on_platform ? "platform" : "base");
  j.key("accuracy").begin_object();
  j.field("stations", static_cast<int>(acc.gauge.size())).field("station_seed", static_cast<double>(run.seed));
  j.key("range").begin_array().value(run.translation).value(run.rotation).end_array();
  j.field("gauge_median", acc.gauge_median)
      .field("gauge_max", acc.gauge_max)
      .field("aligned_median", acc.aligned_median)
      .field("aligned_max", acc.aligned_max)
      .end_object();
  j.end_object();
  return j.str();
}

int run_compare(const CompareOptions& o) {
  for (const auto& [name, path] : {std::pair{"A", &o.a}, std::pair{"B", &o.b}})
    if (path->empty()) throw ExitError(kExitBadInput, fmt::format("{}: expected a configuration file, got ''", name));
  const Model a = load_model_from(ModelOptions{o.a, "A"});
  const Model b = load_model_from(ModelOptions{o.b, "B"});
  StationsSpec run;
  range_option(o.range, run);
  run.count = o.stations;
  run.seed = o.station_seed;
  std::vector<Vector6d> stations;
  try {
    stations = random_stations(a, Strategy::Compensated, run);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, fmt::format("--stations, --range: {}", e.what()));
  }
  const PlatformDifference d = compare_platforms(a, b);
  CommandAccuracy acc;
  if (const Status s = command_accuracy(a, b, stations, acc); s != Status::Ok)
    throw ExitError(kExitOutOfLimit, fmt::format("{}: A's commands at its stations do not give B a pose: {}",
                                                 printable(o.b), describe(s)));
  write_stdout(o.json ? json_report(o, d, run, acc) : text_report(o, a, d, run, acc));
  return kExitOk;
}

}  // namespace

Command make_compare_command(CLI::App& root) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* app = root.add_subcommand(
      "compare",
      "What changed between two configurations' platforms, joint by joint (B - A: joint centres, axes, leads, "
      "offsets, the drives' references, play and compliance, point A), and where A's compensated commands put point "
      "A on B at random stations (as stations draws them), in the gauge frames and after a rigid re-alignment: a "
      "corrected configuration against the nominal one, against a later calibration, or against the real platform "
      "of a rehearsal (synth's FILE.real.yaml). Prints millimetres, micrometres and degrees; --json is SI.");
  app->add_option("A", o->a, "The first configuration (YAML): its commands")->required();
  app->add_option("B", o->b, "The second configuration (YAML): the platform they drive")->required();
  app->add_option("--stations", o->stations, "Random stations A's commands are tried at, 4 to 10000")
      ->capture_default_str()
      ->check(CLI::Range(kMinAccuracyStations, kMaxStations));
  app->add_option("--station-seed", o->station_seed, "Seed of the stations")->capture_default_str();
  app->add_option("--range", o->range,
                  "X_M,ROT_DEG: the stations within ±X_M [m] of home in x, y, z and ±ROT_DEG [deg] in roll, pitch, "
                  "yaw")
      ->capture_default_str();
  app->add_flag("--json", o->json, "Machine-readable output (SI units: m, rad)");
  return {app, [o] { return run_compare(*o); }};
}

}  // namespace hexatwist::cli
