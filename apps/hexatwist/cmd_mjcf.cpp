// SPDX-License-Identifier: BSD-3-Clause
// hexatwist mjcf: the platform as a MuJoCo model (MJCF XML, mjcf.hpp, docs/theory.md §15).
#include <fmt/format.h>

#include <memory>

#include "cli_common.hpp"
#include "output_files.hpp"

namespace hexatwist::cli {
namespace {

struct MjcfOptions {
  ModelOptions model;
  std::string out;
};

int run_mjcf(const MjcfOptions& o) {
  OutputFiles files("mjcf");
  files.input("--config", o.model.config);
  files.output("--out", o.out);
  const Config config = load_config_from(o.model);
  std::string text = mjcf_model(config.rig);
  // Name the configuration in the header comment ("--" may not appear inside an XML comment).
  std::string source = printable(model_source(o.model));
  for (std::size_t k = source.find("--"); k != std::string::npos; k = source.find("--")) source.replace(k, 2, "- -");
  text.insert(0, fmt::format("<!-- Configuration: {} -->\n", source));
  if (!o.out.empty()) files.add(o.out, text);
  files.finish(o.out.empty() ? text : std::string());
  return kExitOk;
}

}  // namespace

Command make_mjcf_command(CLI::App& root) {
  auto opts = std::make_shared<MjcfOptions>();
  CLI::App* app = root.add_subcommand(
      "mjcf",
      "A MuJoCo model (MJCF XML) of the platform: legs with housing, rotor, screw and rod, the screw-nut "
      "pair and the twist as joint equalities, the platform and payload, motors as actuators (docs/theory.md §15)");
  add_model_options(*app, opts->model);
  app->add_option("--out", opts->out, "Write the XML file here instead of to standard output");
  return {app, [opts] { return run_mjcf(*opts); }};
}

}  // namespace hexatwist::cli
