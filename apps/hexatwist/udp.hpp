// SPDX-License-Identifier: BSD-3-Clause
// UDP endpoints of `hexatwist stream` (POSIX sockets): addresses written udp://HOST:PORT, a
// socket that receives one datagram per pose, and one that sends one datagram per answer.
#pragma once

#include <sys/socket.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace hexatwist::cli {

/// A resolved UDP address.
struct UdpAddress {
  sockaddr_storage addr{};
  socklen_t length = 0;
  std::string host;  ///< as written (or 127.0.0.1), without brackets
  std::string text;  ///< as shown to people: udp://127.0.0.1:9000
};

/// "udp://HOST:PORT" for people (IPv6 hosts in brackets).
std::string udp_text(const std::string& host, int port);

/// True if `spec` starts with "udp://".
bool is_udp(std::string_view spec);

/// Parses "udp://HOST:PORT", "udp://:PORT" (loopback) or "udp://[IPv6]:PORT"; HOST is a numeric
/// address or a name (resolved once). Errors are ExitError(2) naming `option`.
UdpAddress parse_udp_address(std::string_view spec, std::string_view option);

/// The port of a resolved address.
int udp_port(const UdpAddress& a);

/// True for a loopback address (127/8, ::1, ::ffff:127.x.y.z).
bool is_loopback(const UdpAddress& address);

/// True if a datagram from `from` is from the sender `allowed` (port 0 in `allowed`: any port).
/// IPv4 addresses written as IPv6 (::ffff:a.b.c.d) compare as the IPv4 address.
bool same_sender(const UdpAddress& allowed, const sockaddr_storage& from);

/// True if datagrams sent to `peer` arrive at a socket bound to `local` on `local_port` (the port it
/// got): the same port, and the same address, or `local` a wildcard address, or both loopback;
/// IPv4 addresses written as IPv6 (::ffff:127.0.0.1) compare as the IPv4 address.
bool reaches(const UdpAddress& peer, const UdpAddress& local, int local_port);

/// An open UDP socket, closed on destruction.
class UdpSocket {
 public:
  /// Bound to `local` (to receive poses). Errors are ExitError(2) naming `option`.
  static UdpSocket bound(const UdpAddress& local, std::string_view option);
  /// Connected to `peer` (to send answers). Errors are ExitError(2) naming `option`.
  static UdpSocket connected(const UdpAddress& peer, std::string_view option);

  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  /// How long `receive` waits for a datagram [ms]; 0 (the default) waits forever.
  void set_receive_timeout(int timeout_ms);
  /// Asks for a receive buffer of `bytes` (the kernel caps it at net.core.rmem_max); returns what
  /// the socket got. ExitError(2) naming `option` on failure.
  int set_receive_buffer(int bytes, const std::string& option);

  /// Result of a receive.
  enum class Received { Datagram, Timeout, Interrupted };
  /// Waits (up to the receive timeout) for one datagram into `buffer`, in one system call; `size`
  /// is its length and `truncated` says it was longer than the buffer. A signal ends the wait
  /// (Interrupted). Other failures throw ExitError.
  Received receive(std::span<char> buffer, std::size_t& size, bool& truncated);
  /// As receive, without waiting: Timeout at once when no datagram is there (busy polling).
  Received try_receive(std::span<char> buffer, std::size_t& size, bool& truncated);

  /// Sends one datagram. A refusal the kernel reports for an earlier datagram (nobody listening
  /// on loopback) is counted and this one sent again; false if it is refused too. Other failures
  /// throw ExitError.
  bool send(std::string_view data);
  /// Datagrams the peer refused (ICMP port unreachable), as the kernel reported them.
  std::uint64_t refused() const { return refused_; }
  /// Datagrams the kernel dropped on arrival since the socket opened (its receive buffer full).
  std::uint64_t dropped() const;
  /// The sender of the last datagram received.
  const sockaddr_storage& sender() const { return sender_; }

  /// The port the socket is bound to (useful after binding port 0).
  int local_port() const;

 private:
  explicit UdpSocket(int fd) : fd_(fd) {}
  Received receive_with(std::span<char> buffer, std::size_t& size, bool& truncated, int flags);
  int fd_ = -1;
  std::uint64_t refused_ = 0, dropped_ = 0;
  sockaddr_storage sender_{};
};

}  // namespace hexatwist::cli
