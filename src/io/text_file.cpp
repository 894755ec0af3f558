// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/io/text_file.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

// A path as it may appear in a one-line message: control characters escaped.
std::string shown(std::string_view path) {
  std::string out;
  for (const char c : path) {
    const auto u = static_cast<unsigned char>(c);
    out += u < 0x20 || u == 0x7f ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  return out;
}

}  // namespace

std::string read_text_file(const std::string& path, std::string_view what, std::size_t max_bytes) {
  // Non-blocking open: a FIFO without a writer does not hold the open forever.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(fmt::format("{}: cannot read the {}: {}", shown(path), what, std::strerror(errno)));
  const std::unique_ptr<int, void (*)(int*)> closer(new int(fd), [](int* f) {
    ::close(*f);
    delete f;
  });
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw Error(fmt::format("{}: cannot read the {}: {}", shown(path), what, std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) throw Error(fmt::format("{}: is a directory, not a {}", shown(path), what));
  // A pipe, socket or device is read as it comes, with the size bound and a bound on each wait.
  const bool stream = !S_ISREG(st.st_mode);
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) && stream) {
      pollfd p{fd, POLLIN, 0};
      const int ready = ::poll(&p, 1, static_cast<int>(kMaxWaitSeconds * 1000));
      if (ready < 0 && errno == EINTR) continue;
      if (ready == 0)
        throw Error(
            fmt::format("{}: cannot read the {}: nothing arrived for {:g} s (a pipe or device that neither "
                        "ends nor writes)",
                        shown(path), what, kMaxWaitSeconds));
      if (ready < 0) throw Error(fmt::format("{}: cannot read the {}: {}", shown(path), what, std::strerror(errno)));
      continue;
    }
    if (n < 0) throw Error(fmt::format("{}: cannot read the {}: {}", shown(path), what, std::strerror(errno)));
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > max_bytes)
      throw Error(fmt::format("{}: longer than a {} may be, {} bytes (at most {:g} MiB are read)", shown(path), what,
                              max_bytes, static_cast<double>(max_bytes) / (1 << 20)));
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

}  // namespace hexatwist
