// Where a streamed export's bytes go: a descriptor (the recorder's end of
// a download's socket pair, or wirc-export's stdout), each write whole and
// blocking, so a slow reader slows the export instead of filling memory. On
// a socket, a reader gone is an error, not a SIGPIPE.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace wircam::recorder {

class ByteStream {
 public:
  explicit ByteStream(int fd) : fd_(fd) {}
  ByteStream(const ByteStream&) = delete;
  ByteStream& operator=(const ByteStream&) = delete;

  // False once a write failed (the reader gone); then error() says why and
  // every later write fails too.
  bool write(const void* data, size_t size);
  const std::string& error() const { return error_; }
  uint64_t written() const { return written_; }

  // A FILE* writing through this, for writers made for files; the caller
  // closes it (which flushes it), before this goes.
  FILE* openFile();

 private:
  int fd_;
  std::string error_;
  uint64_t written_ = 0;
};

}  // namespace wircam::recorder
