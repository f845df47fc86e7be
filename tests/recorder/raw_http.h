// HTTP/1.1 over a plain socket, for what an HTTP library would hide: the
// exact status line and headers, a request no library would send, a server
// that answers late or not at all.
#pragma once

#include <poll.h>
#include <sys/socket.h>

#include <cstdint>
#include <string>

#include "common/socket.h"

namespace wircam::testing {

// The port of "http://HOST:PORT/".
inline uint16_t portOf(const std::string& url) {
  return static_cast<uint16_t>(std::stoi(url.substr(url.rfind(':') + 1)));
}

// Sends `request` on a fresh connection and reads the answer: up to the
// server's close (`whole`), or only up to the end of its status line. Each
// wait for more is at most `patienceMs`.
inline std::string answerTo(uint16_t port, const std::string& request, bool whole = true,
                            int patienceMs = 5000) {
  auto fd = connectTcp(SocketAddress::loopback(port));
  if (!fd) return "";
  ::send(fd->get(), request.data(), request.size(), MSG_NOSIGNAL);
  std::string answer;
  char chunk[512];
  pollfd p{fd->get(), POLLIN, 0};
  while ((whole || answer.find("\r\n") == std::string::npos) && ::poll(&p, 1, patienceMs) > 0) {
    ssize_t n = ::recv(fd->get(), chunk, sizeof chunk, 0);
    if (n <= 0) break;
    answer.append(chunk, static_cast<size_t>(n));
  }
  return answer;
}

inline std::string statusLine(uint16_t port, const std::string& request) {
  auto answer = answerTo(port, request, false);
  return answer.substr(0, answer.find("\r\n"));
}

// An answer's header `name` (as sent, case-sensitive), or "".
inline std::string headerOf(const std::string& answer, const std::string& name) {
  auto at = answer.find("\r\n" + name + ": ");
  if (at == std::string::npos || at > answer.find("\r\n\r\n")) return "";
  at += name.size() + 4;
  return answer.substr(at, answer.find("\r\n", at) - at);
}

// The body after the headers (all of it, when the answer was read whole).
inline std::string bodyOf(const std::string& answer) {
  auto end = answer.find("\r\n\r\n");
  return end == std::string::npos ? "" : answer.substr(end + 4);
}

}  // namespace wircam::testing
