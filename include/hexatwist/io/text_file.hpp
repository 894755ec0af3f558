// SPDX-License-Identifier: BSD-3-Clause
// Text files read whole, with a bound on their size: the one reader of configuration and data files
// for the CLI, the C API and Python, so that they refuse the same files with the same words.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace hexatwist {

/// Largest configuration read or parsed [bytes]: 1 MiB (the seed's is 5 kB). load_config and
/// load_model refuse longer YAML text too.
inline constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;

/// Largest data file read: a trajectory CSV or a point log [bytes]: 256 MiB (an hour of poses at
/// 1 kHz is about 200 MB), read and parsed in about 2 GB.
inline constexpr std::size_t kMaxDataBytes = std::size_t{256} << 20;

/// Longest wait for more of a file that is a pipe, socket or device [s] (a FIFO whose writer
/// stalls); a regular file never waits.
inline constexpr double kMaxWaitSeconds = 10.0;

/// Reads the whole file `path`, at most `max_bytes` bytes (a device such as /dev/zero is cut off
/// there; a FIFO without a writer reads as empty, one whose writer stalls for kMaxWaitSeconds is
/// refused). The open never blocks. Throws hexatwist::Error with one line "PATH: ..." for a directory, a file that
/// cannot be opened or read ("PATH: cannot read the WHAT: " and the system's reason), or one longer than `max_bytes`.
/// `what` names the file's role ("configuration file").
std::string read_text_file(const std::string& path, std::string_view what, std::size_t max_bytes);

}  // namespace hexatwist
