// SPDX-License-Identifier: BSD-3-Clause
// hexatwist fk: the pose for six leg lengths (geometric, or motor-side with the twist included).
#include <fmt/format.h>

#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "json.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct FkOptionsCli {
  ModelOptions model;
  std::string lengths;
  std::string guess = "0,0,0,0,0,0";
  std::string temperature_c;
  bool motor = false;
  bool json = false;
  int max_iterations = FkOptions{}.max_iterations;
};

int run_fk(const FkOptionsCli& o) {
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  const auto v = parse_numbers(o.lengths, 6, "--lengths", "six leg lengths L1..L6 [m]");
  Vector6d lengths;
  for (int i = 0; i < kLegs; ++i) {
    lengths[i] = v[static_cast<std::size_t>(i)];
    if (!(lengths[i] > 0.0))
      throw ExitError(kExitBadInput,
                      fmt::format("--lengths: value {} ({}) is not a length; expected > 0 m", i + 1, lengths[i]));
  }
  const Pose guess = parse_pose_m_deg(o.guess, "--guess");
  const LengthKind kind = o.motor ? LengthKind::Motor : LengthKind::Geometric;
  FkOptions fo;
  fo.max_iterations = o.max_iterations;
  auto result = std::make_unique<FkResult>();
  LegInputs inputs;
  inputs.temperature = temperature_option(o.temperature_c, model);
  if (!o.temperature_c.empty() && !o.motor)
    throw ExitError(kExitBadInput,
                    "--temperature-c: give it with --motor (the drives' lengths, which the legs' "
                    "expansion changes); geometric lengths are the joints' distances already");
  const Status status =
      o.motor ? forward_kinematics(model, lengths, inputs, nullptr, placement_from_pose(guess), *result, fo)
              : forward_kinematics(model, lengths, kind, placement_from_pose(guess), *result, fo);
  LimitReport limit;
  Status final_status = status;
  if (status == Status::Ok) final_status = check_limits(model, result->legs, limit);
  const Vector6d q = result->pose.to_vector();
  const char* kind_name = o.motor ? "motor" : "geometric";

  if (o.json) {
    JsonWriter j;
    j.begin_document(schema::kFk).field("status", to_string(final_status)).field("lengths_kind", kind_name);
    j.key("pose");
    status == Status::Ok ? j.vector(q) : j.null();
    j.field("iterations", result->iterations).field("residual", result->residual);
    j.key("limit");
    write_limit_json(j, limit);
    j.end_object();
    write_stdout(j.str());
  } else {
    std::string out = fmt::format("hexatwist fk on {}{} ({} lengths{})\n", model_source(o.model), defaults_note(config),
                                  kind_name, o.motor ? ", twist included" : "");
    if (status == Status::Ok)
      out += fmt::format("pose: x={:.9f} y={:.9f} z={:.9f} m, roll={:.9f} pitch={:.9f} yaw={:.9f} deg\n", tidy(q[0]),
                         tidy(q[1]), tidy(q[2]), rad2deg(tidy(q[3])), rad2deg(tidy(q[4])), rad2deg(tidy(q[5])));
    out += fmt::format("iterations: {}, residual: {:.3g} m\n", result->iterations, result->residual);
    out += fmt::format("status: {}\n",
                       final_status == Status::Ok ? std::string("ok") : std::string(to_string(final_status)));
    write_stdout(out);
  }
  if (status != Status::Ok) {
    // What the status means for these lengths, not a guess that fits another status.
    const char* why = status == Status::AssemblyModeChanged
                          ? "it converged on another assembly mode than the guess's (the Jacobian's determinant "
                            "changed sign): the platform cannot move there without a singularity; give a --guess on "
                            "the branch you mean"
                      : status == Status::SingularJacobian
                          ? "it met a singular Jacobian: try --guess nearer the pose"
                          : "lengths out of reach, or try --guess near the expected pose";
    std::fprintf(stderr, "hexatwist: forward kinematics failed: %s after %d iterations, residual %.3g m (%s)\n",
                 std::string(to_string(status)).c_str(), result->iterations, result->residual, why);
    return kExitOutOfLimit;
  }
  if (final_status != Status::Ok) {
    std::fprintf(stderr, "hexatwist: pose outside a limit: %s\n", describe(limit).c_str());
    return kExitOutOfLimit;
  }
  return kExitOk;
}

}  // namespace

Command make_fk_command(CLI::App& root) {
  auto opts = std::make_shared<FkOptionsCli>();
  CLI::App* app = root.add_subcommand("fk", "Forward kinematics: the platform pose for six leg lengths");
  app->add_option("--lengths", opts->lengths, "Six leg lengths L1,..,L6 in m")->required();
  app->add_flag("--motor", opts->motor,
                "The lengths are motor-side (encoder) lengths: solve with the twist included, giving the actual pose");
  app->add_option("--guess", opts->guess, "Initial pose x,y,z [m], roll,pitch,yaw [deg]; default home")
      ->capture_default_str();
  app->add_option("--max-iterations", opts->max_iterations, "Newton iterations before giving up")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app->add_option("--temperature-c", opts->temperature_c, kTemperatureHelp);
  add_model_options(*app, opts->model);
  app->add_flag("--json", opts->json, "Machine-readable output (SI units: m, rad)");
  return {app, [opts] { return run_fk(*opts); }};
}

}  // namespace hexatwist::cli
