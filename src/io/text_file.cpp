#include "hexatwist/io/text_file.hpp"

#include <fmt/format.h>

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
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(fmt::format("{}: is a directory, not a {}", shown(path), what));
  errno = 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file)
    throw Error(fmt::format("{}: cannot read the {}: {}", shown(path), what,
                            errno != 0 ? std::strerror(errno) : "cannot open"));
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const std::size_t n = std::fread(buffer, 1, sizeof buffer, file.get());
    if (text.size() + n > max_bytes)
      throw Error(fmt::format("{}: longer than a {} may be, {} bytes (at most {:g} MiB are read)", shown(path), what,
                              max_bytes, static_cast<double>(max_bytes) / (1 << 20)));
    text.append(buffer, n);
    if (n < sizeof buffer) break;
  }
  if (std::ferror(file.get()))
    throw Error(
        fmt::format("{}: cannot read the {}: {}", shown(path), what, errno != 0 ? std::strerror(errno) : "read error"));
  return text;
}

}  // namespace hexatwist
