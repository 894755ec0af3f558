// SPDX-License-Identifier: BSD-3-Clause
// hexatwist mjcf: the MuJoCo model of the platform.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

TEST(CliMjcf, WritesTheMujocoModelToStdoutOrAFileAndNoFileOnBadInput) {
  const Outcome r = run({"mjcf"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("<!-- Configuration: embedded seed platform -->\n", 0), 0u);
  EXPECT_NE(r.out.find("<mujoco model=\"hexatwist\">"), std::string::npos);
  EXPECT_NE(r.out.find("<motor name=\"motor6\""), std::string::npos);
  EXPECT_EQ(r.out.substr(r.out.size() - 10), "</mujoco>\n");
  const std::string out = (temp_dir() / "platform.xml").string();
  std::filesystem::remove(out);
  ASSERT_EQ(run({"mjcf", "--out", out}).code, 0);
  EXPECT_EQ(read_file(out), r.out);
  // A configuration that does not parse, and one MuJoCo cannot represent (lead 0: no screw):
  // one line, exit 2, and no file.
  const std::string bad_out = (temp_dir() / "bad_platform.xml").string();
  std::filesystem::remove(bad_out);
  const std::string malformed = write_file("mjcf_malformed.yaml", replace_line(kSymmetric, 4, "  Rb: abc"));
  expect_error(run({"mjcf", "--config", malformed, "--out", bad_out}), 2, {"mjcf_malformed.yaml", "Rb"});
  const std::string plain = write_file("mjcf_plain.yaml", replace_line(kSymmetric, 9, "  lead: 0"));
  expect_error(run({"mjcf", "--config", plain, "--out", bad_out}), 2, {"mjcf_plain.yaml", "lead"});
  expect_error(run({"mjcf", "--config", (temp_dir() / "missing.yaml").string(), "--out", bad_out}), 2,
               {"missing.yaml"});
  EXPECT_FALSE(std::filesystem::exists(bad_out));
  expect_error(run({"mjcf", "--out", (temp_dir() / "no/such/dir/x.xml").string()}), 4, {"x.xml"});
}

}  // namespace
