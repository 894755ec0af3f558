// SPDX-License-Identifier: BSD-3-Clause
// hexatwist ik: leg lengths, twist, length error and both motor commands for one pose.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "json.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct IkOptions {
  ModelOptions model;
  std::string pose = "0,0,0,0,0,0";
  std::string temperature_c;
  bool json = false;
};

// Why a calibrated configuration's conventional command is not the leg's length (theory §4): the
// drives read motor-side lengths less each leg's zero offset, converted with the drives' own lead
// from their reference. "" when the configuration has none of these.
std::string drive_contract_note(const Model& model, const Vector6d& length, const Vector6d& command) {
  double offset = 0.0, scale = 0.0, differ = 0.0;
  bool homes = false;
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& leg = model.spec().legs[static_cast<std::size_t>(i)];
    offset = std::max(offset, std::abs(leg.length_offset));
    if (std::isfinite(leg.drive_lead)) scale = std::max(scale, std::abs(leg.lead / leg.drive_lead - 1.0));
    homes = homes || std::isfinite(leg.home_command);
    differ = std::max(differ, std::abs(command[i] - length[i]));
  }
  if (offset == 0.0 && scale == 0.0 && !homes) return {};
  std::string why;
  if (offset > 0.0) why += fmt::format("less its zero offset (length_offsets, up to {:.3f} mm)", 1e3 * offset);
  if (scale > 0.0)
    why += fmt::format("{}in the drives' lead, not the screw's (drive_lead; they differ by up to {:.0f} ppm)",
                       why.empty() ? "" : ", ", 1e6 * scale);
  if (homes) why += fmt::format("{}counted from the drives' reference (home_commands)", why.empty() ? "" : ", ");
  return fmt::format(
      "note: command_conv differs from length by up to {:.3f} mm: a calibrated configuration's commands are what each "
      "drive reads (theory §4): the leg's length {}\n",
      1e3 * differ, why);
}

int run_ik(const IkOptions& o) {
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  const Pose pose = parse_pose_m_deg(o.pose, "--pose");
  auto report = std::make_unique<CommandReport>();
  LegInputs inputs;
  inputs.temperature = temperature_option(o.temperature_c, model);
  const Status status = compute_commands(model, pose, inputs, nullptr, *report);
  const bool effects = model.has_leg_effects();
  const LegEffects& e = report->effects;
  // The numbers were finite when parsed (parse_pose_m_deg): so they are too large to compute with.
  if (status == Status::NonFiniteInput)
    throw ExitError(kExitBadInput, fmt::format("--pose {}: too large to compute with (the leg lengths overflow); "
                                               "expected a pose within reach of the platform",
                                               printable(o.pose)));
  const bool ok = status == Status::Ok;
  // The twist (and the length error) exist wherever no U-joint is singular, also outside the
  // other limits; compute_commands leaves them unspecified otherwise.
  LegState legs_check;
  Vector6d twist_check;
  const bool have_twist =
      inverse_kinematics(model, pose, legs_check) == Status::Ok && twist(model, legs_check, twist_check) == Status::Ok;
  Vector6d bend_base, bend_platform, theta;
  bend_angles(model, report->legs, bend_base, bend_platform);
  const bool have_abs = twist_absolute(model, report->legs, theta) == Status::Ok;

  if (o.json) {
    JsonWriter j;
    j.begin_document(schema::kIk).field("status", to_string(status)).field("model", model.spec().name);
    j.key("pose").vector(pose.to_vector());
    j.key("limit");
    write_limit_json(j, report->limit);
    j.key("legs").begin_array(true);
    for (int i = 0; i < kLegs; ++i) {
      j.begin_object().field("leg", i + 1).field("length", report->legs.length[i]);
      j.key("twist");
      have_twist ? j.value(report->twist[i]) : j.null();
      j.key("twist_absolute");
      (have_abs && !std::isnan(model.leg(i).theta_home)) ? j.value(theta[i]) : j.null();
      j.key("length_error");
      have_twist ? j.value(report->length_error[i]) : j.null();
      // A command outside a limit is never emitted.
      j.key("command_conventional");
      ok ? j.value(report->conventional[i]) : j.null();
      j.key("command_compensated");
      ok ? j.value(report->compensated[i]) : j.null();
      j.field("bend_base", bend_base[i]).field("bend_platform", bend_platform[i]);
      // The legs' effects at this pose (theory §4b): real minus rigid length, in its parts.
      if (effects && ok)
        j.field("force", e.force[i])
            .field("temperature", e.temperature[i])
            .field("direction", e.direction[i])
            .field("effect_load", e.load[i])
            .field("effect_thermal", e.thermal[i])
            .field("effect_play", e.play[i])
            .field("effect", e.total[i]);
      j.end_object();
    }
    j.end_array().end_object();
    write_stdout(j.str());
  } else {
    std::string out =
        fmt::format("hexatwist ik on {}: {}{}\n", model_source(o.model), model.spec().name, defaults_note(config));
    out += fmt::format("pose: x={:.6g} y={:.6g} z={:.6g} m, roll={:.6g} pitch={:.6g} yaw={:.6g} deg\n",
                       pose.position.x(), pose.position.y(), pose.position.z(), rad2deg(pose.rpy[0]),
                       rad2deg(pose.rpy[1]), rad2deg(pose.rpy[2]));
    out +=
        "leg  length[m]  twist[deg]  length_error[mm]  command_conv[m]  command_comp[m]  bend_base[deg]  "
        "bend_platform[deg]\n";
    for (int i = 0; i < kLegs; ++i) {
      const std::string tw =
          have_twist ? fmt::format("{:10.4f}", rad2deg(tidy(report->twist[i]))) : fmt::format("{:>10}", "-");
      const std::string le =
          have_twist ? fmt::format("{:16.4f}", 1e3 * tidy(report->length_error[i])) : fmt::format("{:>16}", "-");
      const std::string cc = ok ? fmt::format("{:15.6f}", report->conventional[i]) : fmt::format("{:>15}", "-");
      const std::string cp = ok ? fmt::format("{:15.6f}", report->compensated[i]) : fmt::format("{:>15}", "-");
      out += fmt::format("{:>3}  {:9.6f}  {}  {}  {}  {}  {:14.3f}  {:18.3f}\n", i + 1, report->legs.length[i], tw, le,
                         cc, cp, rad2deg(bend_base[i]), rad2deg(bend_platform[i]));
    }
    if (ok) out += drive_contract_note(model, report->legs.length, report->conventional);
    if (effects && ok) {
      out +=
          "leg effects (real minus rigid length, compensated; each leg approached from home, from the drives' "
          "reference; force: tension positive):\n";
      out += "leg  force[kN]  temperature[degC]  load[um]  thermal[um]  play[um]  total[um]\n";
      for (int i = 0; i < kLegs; ++i)
        out += fmt::format("{:>3}  {:9.3f}  {:17.2f}  {:8.2f}  {:11.2f}  {:8.2f}  {:9.2f}\n", i + 1, 1e-3 * e.force[i],
                           e.temperature[i], 1e6 * tidy(e.load[i]), 1e6 * tidy(e.thermal[i]), 1e6 * tidy(e.play[i]),
                           1e6 * tidy(e.total[i]));
    }
    out += fmt::format("status: {}\n", ok ? "ok" : std::string(to_string(status)) + ": " + describe(report->limit));
    write_stdout(out);
  }
  if (!ok) {
    std::fprintf(stderr, "hexatwist: pose outside a limit: %s\n", describe(report->limit).c_str());
    return kExitOutOfLimit;
  }
  return kExitOk;
}

}  // namespace

Command make_ik_command(CLI::App& root) {
  auto opts = std::make_shared<IkOptions>();
  CLI::App* app = root.add_subcommand(
      "ik", "Inverse kinematics: per leg length, twist (passive rotation), length error, motor commands");
  app->add_option("--pose", opts->pose,
                  "Pose relative to home: x,y,z in m and roll,pitch,yaw in degrees, e.g. --pose=0.1,0,0.2,0,0,15")
      ->capture_default_str();
  app->add_option("--temperature-c", opts->temperature_c, kTemperatureHelp);
  add_model_options(*app, opts->model);
  app->add_flag("--json", opts->json, "Machine-readable output (SI units: m, rad)");
  return {app, [opts] { return run_ik(*opts); }};
}

}  // namespace hexatwist::cli
