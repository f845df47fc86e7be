// What the web server is given of a client's bytes (over TLS, once
// decrypted). libsoup drops a connection whose request head passes its
// 64 KiB bound without a word (the client sees a reset). RFC 9110 has 414
// for a request line that long and 431 for header fields. So each head is held back until its
// blank line, then given whole; a head over the bound is given in its
// place a short request of our own (kOverlongHeadPath) whose answer is the
// 414 or 431, and the rest of it is dropped. A body (a Content-Length's
// worth) passes as it comes; after a chunked one (which the server refuses,
// and closes) or a WebSocket's upgrade nothing is looked at again.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace wircam::recorder {

// libsoup 3's bound on a request's line and header fields together.
inline constexpr size_t kHeadLimit = 64 * 1024;
// The request that stands for an overlong head: ?part=line for 414 (the
// request line alone is over the bound), ?part=fields for 431.
inline constexpr const char* kOverlongHeadPath = "/.wircam/overlong-head";

class RequestHeadFramer {
 public:
  // Bytes from the client; what may go on to the server now is appended
  // to `out` (nothing of a head until it is whole).
  void feed(std::string_view bytes, std::string& out);
  // The client's end: a head held unfinished goes on as it is (the server
  // then sees it cut off).
  void end(std::string& out);
  // The rest of an overlong head is being dropped: the client is still
  // sending what will never be read.
  bool dropping() const { return state_ == State::Dropping; }

 private:
  enum class State { Head, Body, Dropping, Passing };
  // A whole head's next state, from its Content-Length or chunked body.
  void headEnded(std::string_view head);

  State state_ = State::Head;
  std::string held_;         // the head so far
  size_t bodyLeft_ = 0;      // State::Body
  std::string droppedTail_;  // State::Dropping: the last 3 bytes, for a "\r\n\r\n" across reads
};

}  // namespace wircam::recorder
