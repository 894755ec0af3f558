// SPDX-License-Identifier: BSD-3-Clause
// The one reader of configuration and data files (text_file.hpp): the whole file, a bound on its
// size checked while reading (an endless device stops there), and one line naming the path.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <filesystem>
#include <fstream>
#include <string>

#include "hexatwist/error.hpp"
#include "hexatwist/io/text_file.hpp"

namespace hexatwist {
namespace {

namespace fs = std::filesystem;

// A fresh folder for this run's files, removed at exit.
const fs::path& scratch() {
  struct Dir {
    fs::path path;
    Dir() {
      std::string tmpl = (fs::temp_directory_path() / "hexatwist_text_file_XXXXXX").string();
      if (mkdtemp(tmpl.data()) == nullptr) std::abort();
      path = tmpl;
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

std::string error_of(const std::string& path, std::size_t max) {
  try {
    (void)read_text_file(path, "test file", max);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(TextFile, ReadsTheWholeFileUpToItsBoundAndRefusesOneByteMore) {
  const std::string path = (scratch() / "bytes.bin").string();
  std::string bytes;
  for (int k = 0; k < 70000; ++k) bytes += static_cast<char>(k * 7 % 256);  // more than one read's buffer
  std::ofstream(path, std::ios::binary) << bytes;
  EXPECT_EQ(read_text_file(path, "test file", bytes.size()), bytes);
  const std::string msg = error_of(path, bytes.size() - 1);
  EXPECT_NE(msg.find(path + ": longer than a test file may be, 69999 bytes"), std::string::npos) << msg;
}

TEST(TextFile, AFolderAMissingFileAndAnEndlessDeviceAreOneLineEach) {
  std::ofstream((scratch() / "empty").string());
  EXPECT_EQ(read_text_file((scratch() / "empty").string(), "test file", 10), "");
  const std::string folder = error_of(scratch().string(), kMaxConfigBytes);
  EXPECT_NE(folder.find(": is a directory, not a test file"), std::string::npos) << folder;
  const std::string missing = error_of((scratch() / "none" / "x.yaml").string(), kMaxConfigBytes);
  EXPECT_NE(missing.find(": cannot read the test file: No such file or directory"), std::string::npos) << missing;
  const std::string endless = error_of("/dev/zero", kMaxConfigBytes);
  EXPECT_NE(endless.find("/dev/zero: longer than a test file may be, 1048576 bytes"), std::string::npos) << endless;
  for (const std::string& m : {folder, missing, endless}) EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(TextFile, AFifoIsReadWithoutBlockingItsOpen) {
  const fs::path fifo = scratch() / "config.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // No writer: the open does not wait for one, and the file reads as empty.
  EXPECT_EQ(read_text_file(fifo.string(), "test file", kMaxConfigBytes), "");
  // A writer that has written part, and writes the rest while the reader waits: its text, whole.
  const int keep = ::open(fifo.c_str(), O_RDWR);  // holds the FIFO open while the writer joins
  ASSERT_GE(keep, 0);
  const std::string first(50000, 'a'), rest(30000, 'b');
  ASSERT_EQ(::write(keep, first.data(), first.size()), static_cast<ssize_t>(first.size()));
  const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  ASSERT_GE(writer, 0);
  ::close(keep);
  std::string text;
  std::thread reader([&] { text = read_text_file(fifo.string(), "test file", kMaxConfigBytes); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the reader waits on the open writer
  for (std::size_t done = 0; done < rest.size();) {
    const ssize_t n = ::write(writer, rest.data() + done, rest.size() - done);
    if (n > 0) done += static_cast<std::size_t>(n);
  }
  ::close(writer);
  reader.join();
  EXPECT_EQ(text.size(), first.size() + rest.size());
  EXPECT_TRUE(text == first + rest) << "the text read differs from the text written";
}

}  // namespace
}  // namespace hexatwist
