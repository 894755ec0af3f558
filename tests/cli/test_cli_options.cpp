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

}  // namespace
