// SPDX-License-Identifier: BSD-3-Clause
// The tool as a whole: subcommands, help and version.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

TEST(Cli, UnknownSubcommandOrOptionIsBadInput) {
  expect_error(run({"bogus"}), 2, {"'bogus'", "ik, fk, config, linuxcnc, mjcf or compare"});
  expect_error(run({}), 2, {"subcommand"});
  expect_error(run({"ik", "--bogus"}), 2, {"--bogus"});
  expect_error(run({"fk"}), 2, {"--lengths"});
  expect_error(run({"fk", "--lengths=1.9,1.9,1.9,1.9,1.9,1.9", "--max-iterations=0"}), 2, {"--max-iterations"});
}

TEST(Cli, HelpAndVersionExitZero) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"}, {"ik", "--help"}, {"fk", "--help"}, {"config", "--help"}}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.code, 0) << r.command;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << r.command;
    EXPECT_EQ(r.err, "") << r.command;
  }
  const Outcome v = run({"--version"});
  EXPECT_EQ(v.code, 0);
  // The version written once (hexatwist/version.hpp) and read by CMake for the packages.
  EXPECT_EQ(v.out, std::string("hexatwist ") + HEXATWIST_PROJECT_VERSION + "\n");
}

}  // namespace
