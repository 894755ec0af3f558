// SPDX-License-Identifier: BSD-3-Clause
// hexatwist linuxcnc: a LinuxCNC INI file for a platform driven by the hexatwistkins module, with
// the numbers a LinuxCNC configuration needs from the kinematics ([TRAJ] HOME, each joint's HOME,
// HOME_OFFSET and limits, each axis' reach).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "output_files.hpp"

namespace hexatwist::cli {
namespace {

struct LinuxcncOptions {
  ModelOptions model;
  std::string units = "mm";
  std::string strategy = "compensated";
  std::string display = "axis";
  std::string out;
};

// LinuxCNC's own name of each world coordinate.
constexpr const char* kAxisNames[6] = {"X", "Y", "Z", "A", "B", "C"};

// Nine decimals: a nanometre of a length in mm, well below what LinuxCNC resolves.
std::string fixed(double v) { return fmt::format("{:.9f}", tidy(v)); }

// `model`: the configuration's, without its play when it has some (LinuxCNC's BACKLASH takes it).
std::string ini_text(const LinuxcncOptions& o, const Config& config, const Model& model,
                     const std::string& command_line) {
  const bool backlash = config.rig.model().has_play();
  const double unit = o.units == "mm" ? 1000.0 : o.units == "inch" ? 1.0 / 0.0254 : 1.0;
  const Strategy strategy = strategy_option(o.strategy);
  const LimitSpec& lim = model.spec().limits;
  const double home_z = model.spec().home_height;
  // The drives' reference: the joints read these at the home switches (home_commands, theory §4),
  // LinuxCNC's HOME_OFFSET. HOME is where each joint then goes: the commands of the nominal home
  // pose, [TRAJ] HOME. On the configuration the drives were set up with the two are the same; on a
  // calibrated one the switches leave the platform a little off home, and the move to HOME after
  // homing takes it to the pose the user expects.
  const Vector6d home_motor = model.home_command();
  Vector6d home_pose_motor;
  LimitReport home_limit;
  if (const Status s = motor_commands(model, Pose{}, strategy, home_pose_motor, home_limit); s != Status::Ok)
    throw ExitError(kExitOutOfLimit, fmt::format("home is outside a limit: {}", describe(home_limit)));
  std::string homed_note;
  if ((home_pose_motor - home_motor).cwiseAbs().maxCoeff() > 1e-9) {
    FkResult at_switches;
    if (forward_kinematics(model, home_motor, LengthKind::Motor, Placement{}, at_switches) == Status::Ok) {
      const Pose& q = at_switches.pose;
      homed_note = fmt::format(
          "# At the home switches (HOME_OFFSET) this calibrated platform stands at X Y Z A B C =\n"
          "# {} {} {} {} {} {}; after homing each joint moves on to its HOME, the commands of this HOME.\n",
          fixed(q.position.x() * unit), fixed(q.position.y() * unit), fixed((home_z + q.position.z()) * unit),
          fixed(rad2deg(q.rpy.x())), fixed(rad2deg(q.rpy.y())), fixed(rad2deg(q.rpy.z())));
    }
  }

  std::string kins = "hexatwistkins";
  if (!o.model.config.empty()) kins += " config=" + std::filesystem::absolute(o.model.config).string();
  if (o.strategy != "compensated") kins += " strategy=" + o.strategy;
  if (o.units != "mm") kins += " units=" + o.units;
  if (backlash) kins += " play=backlash";

  // Speeds: the motors' from the servo section, the axes' from the study's motion profile.
  const ServoSpec& servo = config.rig.servo();
  // The joints are lengths as the drives compute them (drive_lead, theory §4), so a motor's speed
  // limit is the same joint speed whatever lead the screw really has.
  double joint_velocity = std::numeric_limits<double>::infinity();  // [m/s]
  for (int i = 0; i < kLegs; ++i)
    joint_velocity = std::min(joint_velocity, servo.max_speed * config.rig.motor_gain()[i] / model.leg(i).drive_scale);
  const StudySpec& study = config.study;

  std::string t = fmt::format(
      "# LinuxCNC configuration for \"{}\" with the hexatwistkins kinematics module.\n"
      "# Written by: {}\n"
      "# Units: X Y Z and the joints in {} (Z is the height of the platform frame above the base frame),\n"
      "# A B C in degrees (roll, pitch, yaw; R = Rz(C) Ry(B) Rx(A)); joints are motor-side leg lengths.\n"
      "# Joints are simulated (basic_sim.tcl): for real drives, replace the HALFILE with your own HAL file.\n\n",
      model.spec().name, command_line, o.units);
  t += fmt::format(
      "[EMC]\nVERSION = 1.1\nMACHINE = hexatwist hexapod\n\n"
      "[DISPLAY]\nDISPLAY = {}\nPOSITION_OFFSET = RELATIVE\nPOSITION_FEEDBACK = ACTUAL\nCYCLE_TIME = 0.100\n\n"
      "[RS274NGC]\nPARAMETER_FILE = hexatwist.var\n\n"
      "[EMCMOT]\nEMCMOT = motmod\nCOMM_TIMEOUT = 1.0\nSERVO_PERIOD = 1000000\n\n"
      "[TASK]\nTASK = milltask\nCYCLE_TIME = 0.010\n\n"
      "[HAL]\nHALFILE = LIB:basic_sim.tcl -no_use_hal_manualtoolchange -no_simulated_home -no_sim_spindle\n\n"
      "[EMCIO]\nEMCIO = io\nCYCLE_TIME = 0.100\nTOOL_TABLE = hexatwist.tbl\n\n",
      o.display);
  t += fmt::format(
      "[TRAJ]\nCOORDINATES = X Y Z A B C\nLINEAR_UNITS = {}\nANGULAR_UNITS = degree\n"
      "# Home: the platform frame at home_height above the base, no rotation.\n{}"
      "HOME = 0 0 {} 0 0 0\n"
      "# Speeds of the configuration's study motion (study.linear, study.angular_deg).\n"
      "DEFAULT_LINEAR_VELOCITY = {}\nMAX_LINEAR_VELOCITY = {}\nDEFAULT_LINEAR_ACCELERATION = {}\n"
      "MAX_LINEAR_ACCELERATION = {}\nDEFAULT_ANGULAR_VELOCITY = {}\nMAX_ANGULAR_VELOCITY = {}\n"
      "DEFAULT_ANGULAR_ACCELERATION = {}\nMAX_ANGULAR_ACCELERATION = {}\n\n",
      o.units, homed_note, fixed(home_z * unit), fixed(study.linear.velocity * unit),
      fixed(study.linear.velocity * unit), fixed(study.linear.acceleration * unit),
      fixed(study.linear.acceleration * unit), fixed(rad2deg(study.angular.velocity)),
      fixed(rad2deg(study.angular.velocity)), fixed(rad2deg(study.angular.acceleration)),
      fixed(rad2deg(study.angular.acceleration)));
  t += fmt::format("[KINS]\nKINEMATICS = {}\nJOINTS = 6\n", kins);
  if (backlash)
    t += "# The legs have play (leg_effects.play): LinuxCNC's backlash compensation takes it, following each\n"
         "# joint's direction ([JOINT_n]BACKLASH below); the module leaves it out of its kinematics (play=backlash).\n";
  if (model.has_thermal())
    t += fmt::format(
        "# The legs expand (leg_effects): the module reads each leg's temperature from its input pin\n"
        "# hexatwistkins.leg.N.temperature [degC], at {:g} degC (the reference) until set: net your sensors to them\n"
        "# (integrations/linuxcnc/README.md, \"Legs that deflect, warm and have play\").\n",
        model.reference_temperature());
  t += "\n";

  for (int i = 0; i < kLegs; ++i) {
    const std::string at_home =
        homed_note.empty()
            ? fmt::format("At home {} {}", fixed(home_motor[i] * unit), o.units)
            : fmt::format("At the home switch {} {} (HOME_OFFSET), at home {} {} (HOME)", fixed(home_motor[i] * unit),
                          o.units, fixed(home_pose_motor[i] * unit), o.units);
    t += fmt::format(
        "[JOINT_{}]\n# Leg {}: motor-side length. {}; the stroke limits.length_min .. length_max.\n"
        "TYPE = LINEAR\nHOME = {}\nHOME_OFFSET = {}\nHOME_SEQUENCE = 0\nMIN_LIMIT = {}\nMAX_LIMIT = {}\n"
        "# Motor speed limit (servo.max_speed_rpm, lead, gear_ratio); full speed in 0.1 s (not in the config).\n"
        "MAX_VELOCITY = {}\nMAX_ACCELERATION = {}\n{}\n",
        i, i + 1, at_home, fixed(home_pose_motor[i] * unit), fixed(home_motor[i] * unit), fixed(lim.length_min * unit),
        fixed(lim.length_max * unit), fixed(joint_velocity * unit), fixed(10.0 * joint_velocity * unit),
        backlash ? fmt::format("# The leg's play (leg_effects.play), in motor-side length.\nBACKLASH = {}\n",
                               fixed(2.0 * config.rig.model().geometry().half_play[i] /
                                     config.rig.model().leg(i).drive_scale * unit))
                 : std::string());
  }
  for (int k = 0; k < 6; ++k) {
    AxisRange range;
    if (const Status s = axis_range(model, k, strategy, range); s != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("home is outside a limit: {}", describe(range.upper_limit)));
    const bool linear = k < 3;
    const double scale = linear ? unit : rad2deg(1.0);
    const double offset = k == 2 ? home_z * unit : 0.0;
    const auto end = [&](const LimitReport& r) {
      return r.status == Status::Ok ? std::string("search bound") : describe(r);
    };
    t += fmt::format(
        "[AXIS_{}]\n# Reach along {} alone from home: below, {}; above, {}.\nMIN_LIMIT = {}\nMAX_LIMIT = {}\n"
        "MAX_VELOCITY = {}\nMAX_ACCELERATION = {}\n\n",
        kAxisNames[k], kAxisNames[k], end(range.lower_limit), end(range.upper_limit),
        fixed(offset + range.lower * scale), fixed(offset + range.upper * scale),
        fixed((linear ? study.linear.velocity : study.angular.velocity) * scale),
        fixed((linear ? study.linear.acceleration : study.angular.acceleration) * scale));
  }
  return t;
}

// What LinuxCNC reads back as the value we wrote: an INI value is one line, and the kinematics
// module's arguments (KINEMATICS, read by halcmd's loadrt) are split at white space and quotes.
void check_ini_values(const LinuxcncOptions& o) {
  const auto has = [](const std::string& text, std::string_view chars) {
    return std::any_of(text.begin(), text.end(), [&](char c) {
      const auto u = static_cast<unsigned char>(c);
      return u < 0x20 || u == 0x7f || chars.find(c) != std::string_view::npos;
    });
  };
  if (o.display.empty() || has(o.display, "") || o.display.front() == ' ' || o.display.back() == ' ')
    throw ExitError(kExitBadInput, fmt::format("--display '{}': expected a program name on one line, without control "
                                               "characters or surrounding spaces ([DISPLAY] DISPLAY is one INI value)",
                                               printable(o.display)));
  if (!o.model.config.empty()) {
    const std::string path = std::filesystem::absolute(o.model.config).string();
    if (has(path, " \t\"'\\"))
      throw ExitError(kExitBadInput,
                      fmt::format("--config '{}': its path {} holds a space, quote or control character, which "
                                  "LinuxCNC's loadrt line ([KINS] KINEMATICS config=PATH) cannot carry; move or "
                                  "link the file to a path without them",
                                  printable(o.model.config), printable(path)));
  }
}

int run_linuxcnc(const LinuxcncOptions& o, const std::string& command_line) {
  check_ini_values(o);
  OutputFiles files("linuxcnc");
  files.input("--config", o.model.config);
  files.output("--out", o.out);
  const Config config = load_config_from(o.model);
  // Legs with play: LinuxCNC's backlash compensation takes it (the module's play=backlash), so the
  // INI's homes and ranges are those of the legs without it.
  std::optional<Model> rigid;
  if (config.rig.model().has_play()) {
    ModelSpec spec = config.rig.model().spec();
    for (LegSpec& leg : spec.legs) leg.play = 0.0;
    rigid.emplace(spec);
  }
  const std::string text = ini_text(o, config, rigid ? *rigid : config.rig.model(), command_line);
  if (!o.out.empty()) files.add(o.out, text);
  files.finish(o.out.empty() ? text : std::string());
  return kExitOk;
}

}  // namespace

Command make_linuxcnc_command(CLI::App& root) {
  auto opts = std::make_shared<LinuxcncOptions>();
  CLI::App* app = root.add_subcommand(
      "linuxcnc",
      "A LinuxCNC INI file for the platform with the hexatwistkins kinematics module: [TRAJ] HOME, each "
      "joint's HOME, HOME_OFFSET and stroke limits, each axis' reach from home (integrations/linuxcnc/README.md)");
  add_model_options(*app, opts->model);
  app->add_option("--units", opts->units, "The machine's length unit (LINEAR_UNITS): mm, inch or m")
      ->check(CLI::IsMember({"mm", "inch", "m"}))
      ->capture_default_str();
  app->add_option("--strategy", opts->strategy,
                  "Motor commands of the module: compensated, or conventional (the twist ignored, for comparisons)")
      ->check(CLI::IsMember({"compensated", "conventional"}))
      ->capture_default_str();
  app->add_option("--display", opts->display, "[DISPLAY] DISPLAY: the user interface program (axis, or a script)")
      ->capture_default_str();
  app->add_option("--out", opts->out, "Write the INI file here instead of to standard output");
  return {app, [opts, app] {
            std::string line = "hexatwist linuxcnc";
            for (const CLI::Option* opt : app->get_options())
              if (opt->count() > 0 && opt->get_name() != "--out" && opt->get_name() != "--help")
                line += fmt::format(" {}={}", opt->get_name(), printable(opt->as<std::string>()));
            return run_linuxcnc(*opts, line);
          }};
}

}  // namespace hexatwist::cli
