// SPDX-License-Identifier: BSD-3-Clause
#include "udp.hpp"

#include <fmt/format.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>

#include "cli_common.hpp"

namespace hexatwist::cli {

bool is_udp(std::string_view spec) { return spec.starts_with("udp://"); }

UdpAddress parse_udp_address(std::string_view spec, std::string_view option) {
  const auto bad = [&](std::string_view why) {
    return ExitError(kExitBadInput, fmt::format("{}: '{}' {}; expected udp://HOST:PORT, e.g. udp://127.0.0.1:9000",
                                                option, printable(spec), why));
  };
  if (!is_udp(spec)) throw bad("is not a UDP address");
  std::string_view rest = spec.substr(6);
  std::string host;
  std::string_view port_text;
  if (rest.starts_with("[")) {  // [IPv6]:PORT
    const auto close = rest.find(']');
    if (close == std::string_view::npos || close + 1 >= rest.size() || rest[close + 1] != ':')
      throw bad("has an unclosed [IPv6] address or no :PORT");
    host = std::string(rest.substr(1, close - 1));
    port_text = rest.substr(close + 2);
  } else {
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos) throw bad("has no :PORT");
    host = std::string(rest.substr(0, colon));
    port_text = rest.substr(colon + 1);
  }
  if (host.empty()) host = "127.0.0.1";  // loopback unless asked otherwise
  int port = -1;
  const auto [ptr, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (ec != std::errc() || ptr != port_text.data() + port_text.size() || port < 0 || port > 65535)
    throw bad("has no port number in 0..65535");

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0)
    throw bad(fmt::format("names no host this machine can resolve ({})", gai_strerror(rc)));
  UdpAddress a;
  std::memcpy(&a.addr, found->ai_addr, found->ai_addrlen);
  a.length = found->ai_addrlen;
  freeaddrinfo(found);
  a.host = host;
  a.text = udp_text(host, port);
  return a;
}

int udp_port(const UdpAddress& a) {
  if (a.addr.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&a.addr)->sin_port);
  if (a.addr.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&a.addr)->sin6_port);
  return -1;
}

namespace {

// An IPv4 address written as IPv6 (::ffff:a.b.c.d) as the IPv4 address it is.
UdpAddress unmapped(const UdpAddress& a) {
  if (a.addr.ss_family != AF_INET6) return a;
  const auto& six = reinterpret_cast<const sockaddr_in6&>(a.addr);
  if (!IN6_IS_ADDR_V4MAPPED(&six.sin6_addr)) return a;
  UdpAddress v4 = a;
  v4.addr = {};
  auto& four = reinterpret_cast<sockaddr_in&>(v4.addr);
  four.sin_family = AF_INET;
  four.sin_port = six.sin6_port;
  std::memcpy(&four.sin_addr, six.sin6_addr.s6_addr + 12, 4);
  v4.length = sizeof(sockaddr_in);
  return v4;
}

}  // namespace

bool is_loopback(const UdpAddress& address) {
  const UdpAddress a = unmapped(address);
  if (a.addr.ss_family == AF_INET)
    return (ntohl(reinterpret_cast<const sockaddr_in*>(&a.addr)->sin_addr.s_addr) >> 24) == 127;
  return IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<const sockaddr_in6*>(&a.addr)->sin6_addr);
}

bool same_sender(const UdpAddress& allowed, const sockaddr_storage& from) {
  UdpAddress f;
  f.addr = from;
  const UdpAddress a = unmapped(allowed), b = unmapped(f);
  if (a.addr.ss_family != b.addr.ss_family) return false;
  const int port = udp_port(a);
  if (port != 0 && port != udp_port(b)) return false;
  if (a.addr.ss_family == AF_INET)
    return reinterpret_cast<const sockaddr_in*>(&a.addr)->sin_addr.s_addr ==
           reinterpret_cast<const sockaddr_in*>(&b.addr)->sin_addr.s_addr;
  return std::memcmp(&reinterpret_cast<const sockaddr_in6*>(&a.addr)->sin6_addr,
                     &reinterpret_cast<const sockaddr_in6*>(&b.addr)->sin6_addr, sizeof(in6_addr)) == 0;
}

bool reaches(const UdpAddress& peer_as_written, const UdpAddress& local_as_written, int local_port) {
  const UdpAddress peer = unmapped(peer_as_written), local = unmapped(local_as_written);
  if (udp_port(peer) != local_port) return false;
  const auto kind = [](const UdpAddress& a) {  // 0 wildcard, 1 loopback, 2 other
    if (a.addr.ss_family == AF_INET) {
      const std::uint32_t ip = ntohl(reinterpret_cast<const sockaddr_in*>(&a.addr)->sin_addr.s_addr);
      return ip == INADDR_ANY ? 0 : (ip >> 24) == 127 ? 1 : 2;
    }
    const in6_addr& ip = reinterpret_cast<const sockaddr_in6*>(&a.addr)->sin6_addr;
    return IN6_IS_ADDR_UNSPECIFIED(&ip) ? 0 : IN6_IS_ADDR_LOOPBACK(&ip) ? 1 : 2;
  };
  const int l = kind(local), p = kind(peer);
  if (l == 0 || (l == 1 && p == 1)) return true;
  if (peer.addr.ss_family != local.addr.ss_family) return false;
  if (peer.addr.ss_family == AF_INET)
    return reinterpret_cast<const sockaddr_in*>(&peer.addr)->sin_addr.s_addr ==
           reinterpret_cast<const sockaddr_in*>(&local.addr)->sin_addr.s_addr;
  return std::memcmp(&reinterpret_cast<const sockaddr_in6*>(&peer.addr)->sin6_addr,
                     &reinterpret_cast<const sockaddr_in6*>(&local.addr)->sin6_addr, sizeof(in6_addr)) == 0;
}

std::string udp_text(const std::string& host, int port) {
  return host.find(':') != std::string::npos ? fmt::format("udp://[{}]:{}", host, port)
                                             : fmt::format("udp://{}:{}", host, port);
}

namespace {

int open_socket(const UdpAddress& a, std::string_view option) {
  const int fd = ::socket(a.addr.ss_family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0)
    throw ExitError(kExitBadInput, fmt::format("{}: cannot open a UDP socket: {}", option, std::strerror(errno)));
  return fd;
}

}  // namespace

UdpSocket UdpSocket::bound(const UdpAddress& local, std::string_view option) {
  UdpSocket s(open_socket(local, option));
  // The kernel counts the datagrams it dropped for want of buffer space (read with each datagram).
  const int on = 1;
  ::setsockopt(s.fd_, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  if (::bind(s.fd_, reinterpret_cast<const sockaddr*>(&local.addr), local.length) != 0)
    throw ExitError(kExitBadInput,
                    fmt::format("{}: cannot listen on {}: {}", option, local.text, std::strerror(errno)));
  return s;
}

UdpSocket UdpSocket::connected(const UdpAddress& peer, std::string_view option) {
  UdpSocket s(open_socket(peer, option));
  if (::connect(s.fd_, reinterpret_cast<const sockaddr*>(&peer.addr), peer.length) != 0)
    throw ExitError(kExitBadInput, fmt::format("{}: cannot send to {}: {}", option, peer.text, std::strerror(errno)));
  int stale = 0;  // an error queued before this run is not this run's
  socklen_t len = sizeof stale;
  ::getsockopt(s.fd_, SOL_SOCKET, SO_ERROR, &stale, &len);
  return s;
}

UdpSocket::UdpSocket(UdpSocket&& other) noexcept : fd_(other.fd_), refused_(other.refused_), dropped_(other.dropped_) {
  other.fd_ = -1;
}

UdpSocket& UdpSocket::operator=(UdpSocket&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    refused_ = other.refused_;
    dropped_ = other.dropped_;
    other.fd_ = -1;
  }
  return *this;
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpSocket::set_receive_timeout(int timeout_ms) {
  timeval tv{};
  tv.tv_sec = timeout_ms / 1000;
  tv.tv_usec = (timeout_ms % 1000) * 1000;
  if (::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv) != 0)
    throw ExitError(kExitBadInput, fmt::format("--idle-timeout: {}", std::strerror(errno)));
}

int UdpSocket::set_receive_buffer(int bytes, const std::string& option) {
  if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes) != 0)
    throw ExitError(kExitBadInput, fmt::format("{}: {}", option, std::strerror(errno)));
  int got = 0;
  socklen_t len = sizeof got;
  if (::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &got, &len) != 0) return -1;
  return got;  // the kernel doubles the request for its bookkeeping
}

UdpSocket::Received UdpSocket::receive(std::span<char> buffer, std::size_t& size, bool& truncated) {
  return receive_with(buffer, size, truncated, 0);
}

UdpSocket::Received UdpSocket::try_receive(std::span<char> buffer, std::size_t& size, bool& truncated) {
  return receive_with(buffer, size, truncated, MSG_DONTWAIT);
}

UdpSocket::Received UdpSocket::receive_with(std::span<char> buffer, std::size_t& size, bool& truncated, int flags) {
  // MSG_TRUNC: the return value is the datagram's real length, also when it did not fit. The
  // sender's address and the kernel's drop count come with it.
  iovec io{buffer.data(), buffer.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(std::uint32_t))];
  msghdr m{};
  m.msg_name = &sender_;
  m.msg_namelen = sizeof sender_;
  m.msg_iov = &io;
  m.msg_iovlen = 1;
  m.msg_control = control;
  m.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd_, &m, MSG_TRUNC | flags);
  if (n >= 0)
    for (cmsghdr* c = CMSG_FIRSTHDR(&m); c != nullptr; c = CMSG_NXTHDR(&m, c))
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t count = 0;
        std::memcpy(&count, CMSG_DATA(c), sizeof count);
        dropped_ = count;  // cumulative since the socket was opened
      }
  if (n < 0) {
    if (errno == EINTR) return Received::Interrupted;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return Received::Timeout;
    throw ExitError(kExitOutputFailed, fmt::format("receiving a pose: {}", std::strerror(errno)));
  }
  truncated = static_cast<std::size_t>(n) > buffer.size();
  size = truncated ? buffer.size() : static_cast<std::size_t>(n);
  return Received::Datagram;
}

bool UdpSocket::send(std::string_view data) {
  // ECONNREFUSED is the port-unreachable answer to an earlier datagram, reported by this send
  // (which sent nothing): counted for that one, and this one sent again.
  for (int refusals = 0;;) {
    if (::send(fd_, data.data(), data.size(), 0) >= 0) return true;
    if (errno == EINTR) continue;
    if (errno == ECONNREFUSED) {
      ++refused_;
      if (++refusals < 2) continue;
      return false;
    }
    throw ExitError(kExitOutputFailed, fmt::format("sending an answer: {}", std::strerror(errno)));
  }
}

std::uint64_t UdpSocket::dropped() const {
  // The kernel's count now (the "drops" column of /proc/net/udp and udp6, found by the socket's
  // inode); the count that came with the last datagram where /proc is not there.
  struct stat st {};
  if (::fstat(fd_, &st) != 0) return dropped_;
  for (const char* table : {"/proc/net/udp", "/proc/net/udp6"}) {
    std::FILE* f = std::fopen(table, "r");
    if (f == nullptr) continue;
    char line[512];
    std::uint64_t found = 0;
    bool hit = false;
    while (!hit && std::fgets(line, sizeof line, f) != nullptr) {
      // sl local rem st tx:rx tr:when retrnsmt uid timeout inode ref pointer drops
      unsigned long long inode = 0, drops = 0;
      if (std::sscanf(line, "%*s %*s %*s %*s %*s %*s %*s %*s %*s %llu %*s %*s %llu", &inode, &drops) == 2 &&
          inode == st.st_ino) {
        found = drops;
        hit = true;
      }
    }
    std::fclose(f);
    if (hit) return found;
  }
  return dropped_;
}

int UdpSocket::local_port() const {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) return -1;
  if (a.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&a)->sin_port);
  if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&a)->sin6_port);
  return -1;
}

}  // namespace hexatwist::cli
