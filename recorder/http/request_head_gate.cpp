#include "http/request_head_gate.h"

#include <sys/socket.h>

#include <cerrno>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace wircam::recorder {

namespace {

// A head still unfinished at kHeadWatchedFrom is looked at again this
// often (not on the socket's readiness, which stays on while the bytes
// wait unread), for as long as libsoup would wait for it.
constexpr guint kPeekAgainMs = 20;
constexpr gint64 kWaitForHeadUs = 10'000'000;

struct Gate {
  GSocketConnection* connection;  // owned reference
  std::function<void(GSocketConnection*)> handOn;
  gint64 since = g_get_monotonic_time();
  size_t drained = 0;
  GSource* drainWatch = nullptr;  // owned, while the answered client is drained
  guint timer = 0;
};

// One buffer for every peek and drain: the gate runs on the main loop only,
// and a connection's first look is not worth a 64 KiB allocation (zeroed).
std::vector<char>& scratch() {
  static std::vector<char> buffer(kHeadLimit + 1);
  return buffer;
}

int fdOf(const Gate* gate) {
  return g_socket_get_fd(g_socket_connection_get_socket(gate->connection));
}

void handOnAndForget(Gate* gate) {
  gate->handOn(gate->connection);
  g_object_unref(gate->connection);
  delete gate;
}

void closeAndForget(Gate* gate) {
  if (gate->timer) g_source_remove(gate->timer);
  if (gate->drainWatch) {
    g_source_destroy(gate->drainWatch);
    g_source_unref(gate->drainWatch);
  }
  g_io_stream_close(G_IO_STREAM(gate->connection), nullptr, nullptr);
  g_object_unref(gate->connection);
  delete gate;
}

// What the client still sends is read and thrown away, so that closing
// does not reset the connection before it has read the answer.
gboolean drain(GSocket*, GIOCondition, gpointer data) {
  auto* gate = static_cast<Gate*>(data);
  auto& sink = scratch();
  ssize_t n;
  while ((n = recv(fdOf(gate), sink.data(), sink.size(), MSG_DONTWAIT)) > 0) {
    gate->drained += static_cast<size_t>(n);
    if (gate->drained >= kDrainBytes) break;
  }
  bool more = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
  if (more && gate->drained < kDrainBytes) return G_SOURCE_CONTINUE;
  closeAndForget(gate);
  return G_SOURCE_REMOVE;
}

void answer(Gate* gate, HeadVerdict verdict) {
  bool uri = verdict == HeadVerdict::UriTooLong;
  std::string why = uri ? "the request line is over 64 KiB: shorten the URL's query"
                        : "the request's line and header fields are over 64 KiB together: send "
                          "fewer or shorter headers";
  std::string body = nlohmann::json{{"error", why}}.dump();
  std::string response =
      std::string("HTTP/1.1 ") +
      (uri ? "414 URI Too Long" : "431 Request Header Fields Too Large") +
      "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
      "\r\nConnection: close\r\n\r\n" + body;
  int fd = fdOf(gate);
  // A few hundred bytes into an empty send buffer: whole, or the client is gone.
  (void)send(fd, response.data(), response.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  shutdown(fd, SHUT_WR);
  GSocket* socket = g_socket_connection_get_socket(gate->connection);
  gate->drainWatch = g_socket_create_source(socket, G_IO_IN, nullptr);
  g_source_set_callback(gate->drainWatch, G_SOURCE_FUNC(+drain), gate, nullptr);
  g_source_attach(gate->drainWatch, nullptr);
  gate->timer = g_timeout_add(
      static_cast<guint>(kDrainTime.count()),
      [](gpointer data) -> gboolean {
        auto* g = static_cast<Gate*>(data);
        g->timer = 0;
        closeAndForget(g);
        return G_SOURCE_REMOVE;
      },
      gate);
}

enum class Look { Done, NothingYet, LongAndUnfinished };

// Looks at what has come: handed on or answered (Done), or waited for.
Look look(Gate* gate) {
  auto& head = scratch();
  ssize_t n = recv(fdOf(gate), head.data(), head.size(), MSG_PEEK | MSG_DONTWAIT);
  // (Woken with nothing to read: the socket's own timeout.)
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return Look::NothingYet;
  if (n <= 0) {  // closed or failed: libsoup sees that for itself
    handOnAndForget(gate);
    return Look::Done;
  }
  auto peeked = static_cast<size_t>(n);
  auto verdict = judgeHead(std::string_view(head.data(), peeked));
  if (verdict == HeadVerdict::UriTooLong || verdict == HeadVerdict::FieldsTooLarge) {
    answer(gate, verdict);
    return Look::Done;
  }
  if (verdict == HeadVerdict::Whole || peeked < kHeadWatchedFrom ||
      g_get_monotonic_time() - gate->since > kWaitForHeadUs) {
    handOnAndForget(gate);
    return Look::Done;
  }
  return Look::LongAndUnfinished;
}

gboolean peekAgain(gpointer data) {
  auto* gate = static_cast<Gate*>(data);
  return look(gate) == Look::Done ? G_SOURCE_REMOVE : G_SOURCE_CONTINUE;
}

gboolean firstBytes(GSocket*, GIOCondition, gpointer data) {
  auto* gate = static_cast<Gate*>(data);
  switch (look(gate)) {
    case Look::Done:
      return G_SOURCE_REMOVE;
    case Look::NothingYet:
      return G_SOURCE_CONTINUE;
    case Look::LongAndUnfinished:
      // Looked at again on a timer from now on (the socket stays readable).
      g_timeout_add(kPeekAgainMs, peekAgain, gate);
      return G_SOURCE_REMOVE;
  }
  return G_SOURCE_REMOVE;
}

}  // namespace

HeadVerdict judgeHead(std::string_view peeked) {
  size_t end = peeked.find("\r\n\r\n");
  size_t length = end == std::string_view::npos ? std::string_view::npos : end + 4;
  if (length <= kHeadLimit) return HeadVerdict::Whole;
  if (peeked.size() <= kHeadLimit) return HeadVerdict::Unfinished;
  size_t line = peeked.find('\n');
  return line == std::string_view::npos || line >= kHeadLimit ? HeadVerdict::UriTooLong
                                                              : HeadVerdict::FieldsTooLarge;
}

void gateRequestHead(GSocketConnection* connection,
                     std::function<void(GSocketConnection*)> handOn) {
  auto* gate = new Gate{G_SOCKET_CONNECTION(g_object_ref(connection)), std::move(handOn)};
  GSocket* socket = g_socket_connection_get_socket(connection);
  GSource* readable = g_socket_create_source(socket, G_IO_IN, nullptr);
  g_source_set_callback(readable, G_SOURCE_FUNC(+firstBytes), gate, nullptr);
  g_source_attach(readable, nullptr);
  g_source_unref(readable);
}

}  // namespace wircam::recorder
