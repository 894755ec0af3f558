// SPDX-License-Identifier: BSD-3-Clause
// The one writer of every command's files (output_files.hpp): standard output checked, sets of
// files all or none, outputs compared with inputs as files, reused folders.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>

#include <chrono>
#include <map>

#include "cli_support.hpp"
#include "command_table.hpp"

using namespace hexatwist::cli_test;

namespace {

// ----- no silent failures (#12): every run means what it says or says why not -----

TEST(CliOutputs, EveryCommandWritingToAFullStandardOutputExitsFour) {
  const std::vector<std::vector<std::string>> commands = {
      {"ik", "--pose=0,0,0.1,0,0,30"},
      {"ik", "--pose=0,0,0.1,0,0,30", "--json"},
      {"fk", "--lengths=1.700685245,2.377495057,1.700685245,2.377495057,1.700685245,2.377495057", "--motor"},
      {"fk", "--lengths=1.700685245,2.377495057,1.700685245,2.377495057,1.700685245,2.377495057", "--json"},
      {"config"},
      {"config", "--json"},
      {"config", "--yaml"},
      {"linuxcnc"},
      {"--help"},
      {"ik", "--help"},
      {"--version"}};
  for (const auto& args : commands) {
    const Outcome r = run_to_full_disk(args);
    expect_error(r, 4, {"standard output"});
  }
}

TEST(CliOutputs, SynthOutputsThatNameTheSameFileAreRefusedBeforeAnythingIsWritten) {
  const std::filesystem::path c = temp_dir() / "same.csv";
  std::filesystem::remove(c);
  expect_error(run({"synth", "--test", "Lz", "--out", c.string(), "--run-out", c.string()}), 2,
               {"--out", "--run-out", "same.csv", "nothing was written"});
  EXPECT_FALSE(std::filesystem::exists(c));
  const std::string truth = (temp_dir() / "same.truth.json").string();
  expect_error(run({"synth", "--test", "Lz", "--out", c.string(), "--run-out", truth}), 2, {"--run-out", "truth"});
  EXPECT_FALSE(std::filesystem::exists(truth));
}

TEST(CliOutputs, AReportThatCannotBeWrittenWholeLeavesNoFileAndNoTemporary) {
  const std::string csv = write_file("blocked.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "blocked-out";
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out / "summary.json");  // a folder where the summary goes
  expect_error(run({"simulate", "--trajectory", csv, "--out", out.string()}), 4, {"summary.json"});
  EXPECT_EQ(folder_entries(out), std::vector<std::string>{"summary.json"});
}

TEST(CliOutputs, AReusedFolderSaysSoAndItsSummaryListsOnlyThisRunsFiles) {
  const std::string csv = write_file("reused.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "reused-out";
  std::filesystem::remove_all(out);
  const Outcome first = run({"simulate", "--trajectory", csv, "--out", out.string(), "--no-figures"});
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_EQ(first.err, "");
  EXPECT_TRUE(std::filesystem::exists(out / "reused_compensated.csv"));
  write_file("reused-out/notes.txt", "mine\n");
  const Outcome second = run({"simulate", "--trajectory", csv, "--out", out.string(), "--no-figures", "--no-csv"});
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_NE(second.err.find("was not empty: 2 files replaced, 2 of an earlier run removed; 1 other file left"),
            std::string::npos)
      << second.err;
  EXPECT_NE(second.err.find("notes.txt"), std::string::npos);
  EXPECT_EQ(folder_entries(out),
            (std::vector<std::string>{".hexatwist-run.json", "notes.txt", "summary.json", "summary.md"}));
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  EXPECT_EQ(s["files"].size(), 0u);
  EXPECT_EQ(read_file(out / "summary.md").find("_compensated.csv"), std::string::npos);
}

TEST(CliOutputs, AReportWhoseStandardOutputFailsLeavesNoFiles) {
  const std::string csv = write_file("fullout.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "fullout-out";
  std::filesystem::remove_all(out);
  expect_error(run_to_full_disk({"simulate", "--trajectory", csv, "--out", out.string(), "--no-figures"}), 4,
               {"standard output"});
  // The folder this run made is gone with its files (a failed run leaves nothing it made).
  EXPECT_TRUE(!std::filesystem::exists(out) || folder_entries(out).empty());
  const std::string log = (temp_dir() / "fullout-log.csv").string();
  expect_error(run_to_full_disk({"synth", "--test", "Lz", "--out", log}), 4, {"standard output"});
  EXPECT_FALSE(std::filesystem::exists(log));
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "fullout-log.truth.json"));
}

// ----- nothing lost (#22): a failed run changes nothing that was there before it -----

namespace fs = std::filesystem;

// Every file under `dir` with its bytes (names relative to `dir`).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_file(e.path());
  return files;
}

// A short heave and a configuration whose study tests last half a second: quick reports.
std::string quick_config() {
  return write_file("quick.yaml", hexatwist::test::kSymmetricYaml +
                                      "study:\n  linear_amplitude: 0.01\n  angular_amplitude_deg: 1\n  dwell: 0.05\n"
                                      "  linear: {velocity: 0.5, acceleration: 5, jerk: 50}\n"
                                      "  angular_deg: {velocity: 30, acceleration: 300, jerk: 3000}\n");
}

TEST(CliOutputs, AFailedRunLeavesEveryEarlierFileByteForByte) {
  const std::string config = quick_config();
  const std::string csv = write_file("keep.csv", heave_csv());
  // Stations 20 mm along x, y and z (the tracker frame registers on them), then a yaw and back.
  const std::string stations = write_file("keep-stations.csv",
                                          "t,x_mm,y_mm,z_mm,roll,pitch,yaw\n0,0,0,0,0,0,0\n0.5,0,0,0,0,0,0\n"
                                          "1,20,0,0,0,0,0\n1.5,20,0,0,0,0,0\n2,0,20,0,0,0,0\n2.5,0,20,0,0,0,0\n"
                                          "3,0,0,20,0,0,0\n3.5,0,0,20,0,0,0\n4,0,0,0,0,0,0\n5,0,0,0,0,0,3\n"
                                          "6,0,0,0,0,0,0\n");
  const std::string log = (temp_dir() / "keep-log.csv").string();
  ASSERT_EQ(run({"synth", "--trajectory", stations, "--out", log}).code, 0);
  const std::vector<std::vector<std::string>> runs = {
      {"study", "--config", config, "--tests", "Lz,Rz", "--no-csv"},
      {"simulate", "--trajectory", csv},
      {"dynamics", "--trajectory", csv},
      {"measure", "--points", log, "--trajectory", stations, "--register-until", "4", "--no-figures"},
  };
  for (const std::vector<std::string>& command : runs) {
    const fs::path out = temp_dir() / ("keep-" + command[0]);
    std::vector<std::string> args = command;
    args.insert(args.end(), {"--out", out.string()});
    const Outcome first = run(args);
    ASSERT_EQ(first.code, 0) << first.command << "\n" << first.err;
    write_file("keep-" + command[0] + "/notes.txt", "my notes\n");
    const auto before = snapshot(out);
    ASSERT_GT(before.size(), 2u);
    // The same run again, and one with other files, each failing at its very end.
    std::vector<std::string> other = args;
    if (command[0] == "study") other[std::find(other.begin(), other.end(), "Lz,Rz") - other.begin()] = "Rz";
    for (const auto& again : {args, other}) {
      expect_error(run_to_full_disk(again), 4, {"standard output"});
      EXPECT_EQ(snapshot(out), before) << command[0] << ": the earlier report changed";
    }
  }
  // Files named by the user: synth's log and truth, identify's configuration, beside an input.
  const std::string truth = (temp_dir() / "keep-log.truth.json").string();
  const std::string log_before = read_file(log), truth_before = read_file(truth);
  expect_error(run_to_full_disk({"synth", "--trajectory", stations, "--out", log, "--seed", "7"}), 4,
               {"standard output"});
  EXPECT_EQ(read_file(log), log_before);
  EXPECT_EQ(read_file(truth), truth_before);
}

TEST(CliOutputs, AFailedIdentifyLeavesAHandMadeConfigurationAsItWas) {
  const std::string log = (temp_dir() / "keep-stations.csv").string();
  ASSERT_EQ(run({"synth", "--stations", "20", "--station-seed", "3", "--out", log}).code, 0);
  const std::string keep = write_file("keep.yaml", "# my own configuration\n" + hexatwist::test::kSymmetricYaml);
  const Outcome ok = run({"identify", "--points", log, "--stations", "20", "--station-seed", "3", "--out", keep});
  if (ok.code != 0) GTEST_SKIP() << "this log does not identify: " << ok.err;  // the run must reach its write
  std::ofstream(keep) << "# my own configuration\n" << hexatwist::test::kSymmetricYaml;
  expect_error(
      run_to_full_disk({"identify", "--points", log, "--stations", "20", "--station-seed", "3", "--out", keep}), 4,
      {"standard output"});
  EXPECT_EQ(read_file(keep), "# my own configuration\n" + hexatwist::test::kSymmetricYaml);
}

TEST(CliOutputs, AnOutputThatIsAnInputAsAFileIsRefusedAndTheInputKept) {
  const fs::path dir = temp_dir() / "same-files";
  fs::create_directories(dir);
  const std::string csv = (dir / "run.csv").string();
  std::ofstream(csv) << heave_csv();
  const std::string yaml = (dir / "x.yaml").string();
  std::ofstream(yaml) << hexatwist::test::kSymmetricYaml;
  fs::create_symlink(yaml, dir / "link.yaml");
  fs::create_hard_link(csv, dir / "hard.csv");
  const std::string relative = fs::relative(yaml).string();  // from the test's working folder
  const struct {
    std::vector<std::string> args;
    const char* input;
  } cases[] = {
      {{"synth", "--trajectory", csv, "--out", csv}, "--trajectory"},
      {{"synth", "--trajectory", csv, "--out", (dir / "hard.csv").string()}, "--trajectory"},
      {{"synth", "--trajectory", csv, "--out", (dir / "x.csv").string(), "--run-out", csv}, "--trajectory"},
      {{"linuxcnc", "--config", yaml, "--out", yaml}, "--config"},
      {{"linuxcnc", "--config", relative, "--out", yaml}, "--config"},
      {{"mjcf", "--config", yaml, "--out", (dir / "link.yaml").string()}, "--config"},
      {{"mjcf", "--config", (dir / "link.yaml").string(), "--out", (dir / "." / "x.yaml").string()}, "--config"},
      {{"identify", "--points", csv, "--trajectory", (dir / "t.csv").string(), "--out", csv}, "--points"},
      {{"identify", "--config", yaml, "--points", (dir / "p.csv").string(), "--test", "Lz", "--out", yaml}, "--config"},
      {{"dynamics", "--trajectory", csv, "--out", csv}, "--trajectory"},
  };
  const auto before = snapshot(dir);
  for (const auto& c : cases) {
    expect_error(run(c.args), 2, {c.input, "an output never replaces an input"});
    EXPECT_EQ(snapshot(dir), before);
  }
}

TEST(CliOutputs, TwoOutputsNamingOneFileAreRefusedHoweverTheyAreSpelled) {
  const fs::path dir = temp_dir() / "two-outputs";
  fs::create_directories(dir);
  // In an empty folder, the second name is the first one absolute: one file, refused before
  // anything runs.
  const Outcome r = run({"synth", "--test", "Lz", "--out", (dir / "c.csv").string(), "--run-out",
                         (dir / "sub" / ".." / "c.csv").string()});
  expect_error(r, 2, {"--out", "--run-out", "c.csv", "nothing was written"});
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(CliOutputs, AFolderGivenAsAFileOutputIsRefusedNamingTheOption) {
  expect_error(run({"mjcf", "--out", temp_dir().string()}), 2, {"--out", "is a folder"});
  expect_error(run({"linuxcnc", "--out", temp_dir().string()}), 2, {"--out", "is a folder"});
  expect_error(run({"simulate", "--trajectory", write_file("f.csv", heave_csv()), "--out", ""}), 2, {"--out"});
}

TEST(CliOutputs, AFileOutputInAFolderThatIsNotThereIsRefusedBeforeTheRun) {
  // Every command that writes named files: refused at once (not after the identification or the
  // synthesis), naming the option, the file and the folder; nothing appears.
  const std::string missing = (temp_dir() / "no-such-folder").string();
  const std::string a_file = write_file("plain-file", "x");
  const std::string log = HEXATWIST_SOURCE_DIR "/examples/tracker_stations.csv";
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"identify", "--points", log, "--stations", "40", "--station-seed", "4", "--out"},
        {"synth", "--stations", "14", "--out"},
        {"stations", "--count", "14", "--out"},
        {"mjcf", "--out"},
        {"linuxcnc", "--out"},
        {"design", "--out"}}) {
    for (const std::string& folder : {missing, a_file}) {
      std::vector<std::string> args = command;
      args.push_back(folder + "/out.file");
      expect_error(
          run(args), 4,
          {"--out", "out.file", folder == missing ? "does not exist" : "is not a folder", "nothing was written"});
    }
  }
  EXPECT_FALSE(std::filesystem::exists(missing));
}

TEST(CliOutputs, AFolderReusedByAnotherCommandHoldsOnlyThatRunsFilesAndSaysSo) {
  const std::string csv = write_file("h2.csv", heave_csv());
  const fs::path out = temp_dir() / "H2";
  ASSERT_EQ(run({"simulate", "--trajectory", csv, "--out", out.string(), "--no-figures"}).code, 0);
  EXPECT_TRUE(fs::exists(out / "summary.md"));
  EXPECT_TRUE(fs::exists(out / "h2_compensated.csv"));
  const Outcome r = run({"dynamics", "--trajectory", csv, "--out", out.string(), "--no-figures"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("the earlier run was simulate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 file replaced, 3 of an earlier run removed"), std::string::npos) << r.err;
  EXPECT_EQ(folder_entries(out), (std::vector<std::string>{".hexatwist-run.json", "h2_dynamics.csv", "summary.json"}));
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  EXPECT_EQ(s["command"].as<std::string>(), "dynamics");
}

// ----- walked across the commands (command_table.hpp): links, locks, other programs' files, names -----

// The --out value of a command of the table ("out" is a report folder; empty: none).
std::string out_value(const std::vector<std::string>& args) {
  for (std::size_t k = 0; k + 1 < args.size(); ++k)
    if (args[k] == "--out") return args[k + 1];
  return {};
}

std::vector<std::string> command_line(const std::string& command, const std::vector<std::string>& args) {
  std::vector<std::string> full{command};
  full.insert(full.end(), args.begin(), args.end());
  return full;
}

TEST(CliOutputs, NoCommandWritesThroughALinkSomeoneElsePlanted) {
  const Inputs& in = inputs();
  for (const auto& [command, args] : base_arguments(in)) {
    const std::string out = out_value(args);
    if (out.empty()) continue;
    const fs::path dir = in.dir / ("link-" + command);
    fs::create_directories(dir);
    const fs::path victim = dir / "victims-file.txt";
    std::ofstream(victim) << "the victim's data\n";
    // A file output is the link; a report folder gets one where its run's manifest goes.
    fs::path link = dir / out;
    if (out == "out") {
      fs::create_directories(dir / out);
      link = dir / out / ".hexatwist-run.json";
    }
    fs::create_symlink(victim, link);
    const Outcome r = run_in(dir, command_line(command, args));
    EXPECT_EQ(r.code, 2) << r.command << "\n" << r.err;
    EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
    EXPECT_EQ(read_file(victim), "the victim's data\n") << command;
    EXPECT_TRUE(fs::is_symlink(link)) << command;
    if (out == "out") {
      EXPECT_EQ(std::distance(fs::directory_iterator(dir / out), fs::directory_iterator()), 1);
    }
  }
}

TEST(CliOutputs, ASecondRunIntoAFolderInUseIsRefusedAndWritesNothing) {
  const Inputs& in = inputs();
  int walked = 0;
  for (const auto& [command, args] : base_arguments(in)) {
    if (out_value(args) != "out") continue;
    ++walked;
    const fs::path dir = in.dir / ("lock-" + command);
    fs::create_directories(dir / "out");
    // The other run: a lock on the folder, as a run holds it while it writes.
    const int fd = ::open((dir / "out").c_str(), O_RDONLY | O_DIRECTORY);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    const Outcome r = run_in(dir, command_line(command, args));
    ::close(fd);
    EXPECT_EQ(r.code, 2) << r.command << "\n" << r.err;
    EXPECT_NE(r.err.find("--out 'out': another hexatwist run is writing into this folder"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir / "out")) << command;
    // Once the other run ended, the same command runs.
    EXPECT_TRUE(run_in(dir, command_line(command, args)).code == 0) << command;
  }
  EXPECT_GE(walked, 6);
}

TEST(CliOutputs, AReportFolderNeverRemovesOrReplacesAFileHexatwistCannotShowItMade) {
  const Inputs& in = inputs();
  for (const auto& [command, args] : base_arguments(in)) {
    if (out_value(args) != "out") continue;
    const fs::path dir = in.dir / ("foreign-" + command);
    const fs::path out = dir / "out";
    fs::create_directories(out);
    // Another program's summary and files, and a manifest that claims them with other hashes.
    std::ofstream(out / "raw.csv") << "t,x\n0,1\n";
    std::ofstream(out / "notes.txt") << "my notes\n";
    std::ofstream(out / "summary.json") << R"({"tool": "my-lab-notebook", "files": ["raw.csv", "notes.txt"]})";
    std::ofstream(out / ".hexatwist-run.json")
        << "{\n  \"schema\": \"hexatwist.run/1\",\n  \"command\": \"study\",\n  \"files\": [\n"
           "    {\"name\": \"raw.csv\", \"bytes\": 8, \"fnv1a64\": \"0123456789abcdef\"},\n"
           "    {\"name\": \"notes.txt\", \"bytes\": 9, \"fnv1a64\": \"0123456789abcdef\"}\n  ]\n}\n";
    const Outcome r = run_in(dir, command_line(command, args));
    EXPECT_EQ(read_file(out / "raw.csv"), "t,x\n0,1\n") << command;
    EXPECT_EQ(read_file(out / "notes.txt"), "my notes\n") << command;
    // Every report writes summary.json: the other program's is refused, not replaced.
    EXPECT_EQ(r.code, 2) << r.command << "\n" << r.err;
    EXPECT_NE(r.err.find("'summary.json', which hexatwist did not write"), std::string::npos) << r.err;
    EXPECT_EQ(read_file(out / "summary.json"), R"({"tool": "my-lab-notebook", "files": ["raw.csv", "notes.txt"]})");
    // Without it, the run writes its report, and leaves the other files named.
    fs::remove(out / "summary.json");
    const Outcome ok = run_in(dir, command_line(command, args));
    EXPECT_EQ(ok.code, 0) << ok.err;
    EXPECT_NE(ok.err.find("2 other files left"), std::string::npos) << ok.err;
    EXPECT_EQ(read_file(out / "raw.csv"), "t,x\n0,1\n") << command;
    EXPECT_EQ(read_file(out / "notes.txt"), "my notes\n") << command;
    // A file of that run changed since (the user's edit) is not replaced either.
    std::ofstream(out / "summary.json", std::ios::app) << "\n";
    const std::string edited = read_file(out / "summary.json");
    const Outcome again = run_in(dir, command_line(command, args));
    EXPECT_EQ(again.code, 2) << again.err;
    EXPECT_EQ(read_file(out / "summary.json"), edited) << command;
  }
}

TEST(CliOutputs, AnOversizedManifestIsNotReadAndItsFilesAreKept) {
  const Inputs& in = inputs();
  const auto base = base_arguments(in);
  const fs::path dir = in.dir / "big-manifest";
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "raw.csv") << "keep me\n";
  {
    // A valid manifest of 2 MiB naming raw.csv with its true size and hash: too long to be ours.
    std::ofstream m(out / ".hexatwist-run.json");
    m << "{\n  \"schema\": \"hexatwist.run/1\",\n  \"command\": \"study\",\n  \"files\": [\n";
    m << "    {\"name\": \"raw.csv\", \"bytes\": 8, \"fnv1a64\": \""
      << "0000000000000000"
      << "\"}";
    for (int k = 0; k < 30000; ++k)
      m << ",\n    {\"name\": \"pad" << k << "\", \"bytes\": 1, \"fnv1a64\": \"0000000000000000\"}";
    m << "\n  ]\n}\n";
  }
  ASSERT_GT(fs::file_size(out / ".hexatwist-run.json"), std::size_t{1} << 20);
  const Outcome r = run_in(dir, command_line("study", base.at("study")));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(out / "raw.csv"), "keep me\n");
}

TEST(CliOutputs, ATemporaryNameFitsWhereverTheFinalNameFits) {
  const Inputs& in = inputs();
  const std::string longest(240, 'n');  // NAME_MAX is 255: room for synth's ".truth.json"
  for (const auto& [command, args] : base_arguments(in)) {
    const std::string out = out_value(args);
    if (out.empty() || out == "out") continue;
    const fs::path dir = in.dir / ("long-" + command);
    fs::create_directories(dir);
    std::vector<std::string> a = args;
    for (std::string& w : a)
      if (w == out) w = longest;
    const Outcome r = run_in(dir, command_line(command, a));
    const int expected = command == "identify" ? 5 : 0;
    EXPECT_EQ(r.code, expected) << r.command << "\n" << r.err;
    if (expected == 0) {
      EXPECT_TRUE(fs::exists(dir / longest)) << command;
    }
  }
}

TEST(CliOutputs, AConfigurationThatIsAFifoIsReadWithABoundNotWaitedOnForever) {
  const Inputs& in = inputs();
  const fs::path dir = in.dir / "fifo";
  fs::create_directories(dir);
  const fs::path fifo = dir / "config.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const auto& [command, args] : base_arguments(in)) {
    std::vector<std::string> a = args;
    for (std::string& arg : a)  // --config's value, and a configuration given as an argument (compare)
      if (arg == in.config) arg = fifo.string();
    // No writer: an empty configuration, refused at once (the test's own timeout bounds it).
    const auto t0 = std::chrono::steady_clock::now();
    const Outcome r = run_in(dir, command_line(command, a));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 2) << r.command << "\n" << r.err;
    EXPECT_NE(r.err.find("config.yaml"), std::string::npos) << r.err;
    EXPECT_LT(seconds, 30.0) << command;
  }
}

}  // namespace
