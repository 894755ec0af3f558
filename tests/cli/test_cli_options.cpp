// SPDX-License-Identifier: BSD-3-Clause
// Options: refused out of their range, without effect in the mode, or absurd.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

TEST(CliOptions, UdpOnlyOptionsOnStandardInputAreRefused) {
  const std::string input = "0,0,0.1,0,0,0\n";
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--idle-timeout", "1"}, {"--receive-buffer", "65536"}, {"--busy-poll"}}) {
    std::vector<std::string> args{"stream"};
    args.insert(args.end(), extra.begin(), extra.end());
    expect_error(run(args, &input), 2, {extra[0], "only with --input udp://"});
  }
}

TEST(CliOptions, FiniteButAbsurdStreamAndSettleValuesAreRefusedNamingTheirRange) {
  const std::string none;
  expect_error(run({"stream", "--max-velocity", "1", "--rate", "1e300"}, &none), 2,
               {"--rate 1e+300", "at most 1e6 Hz"});
  expect_error(run({"stream", "--rt-priority", "500"}, &none), 2, {"--rt-priority 500", "SCHED_FIFO priority 1..99"});
  expect_error(run({"stream", "--rt-priority", "-1"}, &none), 2, {"--rt-priority -1", "or 0 for none"});
  const std::string tracker = std::string(HEXATWIST_SOURCE_DIR) + "/examples/tracker_Rz.csv";
  for (const char* command : {"measure", "identify"}) {
    const Outcome r = run({command, "--points", tracker, "--test", "Rz", "--settle", "1e9", "--out",
                           (temp_dir() / "settle-out").string()});
    expect_error(r, 2, {"--settle 1000000000", "shorter than the run"});
  }
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "settle-out"));
}

TEST(CliOptions, AFiniteButHugePoseIsNotCalledNonFinite) {
  const Outcome r = run({"ik", "--pose=1e300,0,0,0,0,0"});
  SCOPED_TRACE(r.err);
  EXPECT_EQ(r.err.find("non-finite"), std::string::npos);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
}

TEST(CliOptions, OptionsWithoutEffectInTheChosenModeAreRefused) {
  const std::string none;
  expect_error(run({"config", "--yaml", "--json"}), 2, {"--json", "--yaml"});
  expect_error(run({"stream", "--rate", "50"}, &none), 2, {"--rate", "--max-velocity"});
}

TEST(CliOptions, UnsignedOptionsRefuseNegativeNumbersInsteadOfWrappingThem) {
  const std::string none;
  expect_error(run({"stream", "--count", "-1"}, &none), 2, {"--count", "whole number >= 0", "'-1'"});
  expect_error(run({"synth", "--test", "Lz", "--seed", "-1", "--out", (temp_dir() / "wrap.csv").string()}), 2,
               {"--seed", "whole number >= 0"});
  expect_error(run({"synth", "--stations", "3", "--station-seed=-5", "--out", (temp_dir() / "wrap.csv").string()}), 2,
               {"--station-seed"});
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "wrap.csv"));
}

TEST(CliStream, OptionsWithoutMeaningInTheirModeAreRefusedAndTheShorthandIsTheAddress) {
  const std::string none;
  expect_error(run({"stream", "--format", "json", "--header"}, &none), 2, {"--header", "--format csv"});
  expect_error(run({"stream", "--max-velocity", "1", "--rate", "1e-300"}, &none), 2,
               {"--max-velocity 1 with --rate 1e-300", "never apply"});
  expect_error(run({"stream", "--max-acceleration", "1e6", "--rate", "1"}, &none), 2,
               {"--max-acceleration", "never apply"});
  expect_error(run({"stream", "--output", "udp://127.0.0.1:0"}, &none), 2, {"--output", "port 0"});
  expect_error(run({"stream", "--cpu", "-1"}, &none), 2, {"--cpu -1", ">= 0"});
  // The same UDP endpoint in and out would answer itself forever.
  expect_error(run({"stream", "--input", "udp://127.0.0.1:47111", "--output", "udp://127.0.0.1:47111"}, &none), 2,
               {"--output", "where --input listens"});
  expect_error(run({"stream", "--input", "udp://0.0.0.0:47112", "--output", "udp://127.0.0.1:47112"}, &none), 2,
               {"--output", "where --input listens"});
  // The documented shorthand is the UDP input: --idle-timeout belongs to it.
  // (Its port, 9000, may be taken on a shared machine: then it cannot listen, but says so.)
  const Outcome r = run({"stream", "--input", "udp", "--output", "udp://127.0.0.1:47113", "--idle-timeout", "0.05"});
  EXPECT_EQ(r.err.find("only with --input"), std::string::npos) << r.err;
  if (r.code == 0)
    EXPECT_NE(r.err.find("no datagram for 0.05 s"), std::string::npos) << r.err;
  else
    expect_error(r, 2, {"--input", "cannot listen on udp://127.0.0.1:9000"});
}

TEST(CliOptions, AForwardKinematicsThatEndsOnAnotherAssemblyModeSaysSo) {
  // Lengths and a guess (found by a seeded search) whose solution lies on another assembly mode:
  // the lengths are within reach, and the message says what happened.
  const Outcome r = run(
      {"fk", "--lengths=1.6846,1.8329,2.1050,2.0978,2.2555,1.8955", "--guess=0.338,0.056,0.035,-37.691,59.105,86.387"});
  expect_error(r, 3, {"assembly_mode_changed", "another assembly mode"});
  EXPECT_EQ(r.err.find("out of reach"), std::string::npos) << r.err;
}

}  // namespace
