#include "export/byte_stream.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace wircam::recorder {

bool ByteStream::write(const void* data, size_t size) {
  if (!error_.empty()) return false;
  const auto* bytes = static_cast<const char*>(data);
  bool socket = true;
  while (size > 0) {
    ssize_t sent = socket ? ::send(fd_, bytes, size, MSG_NOSIGNAL) : ::write(fd_, bytes, size);
    if (sent < 0 && errno == ENOTSOCK && socket) {
      socket = false;  // a pipe or a file
      continue;
    }
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) {
      error_ = errno == EPIPE || errno == ECONNRESET
                   ? "the reader is gone"
                   : std::string("cannot write: ") + std::strerror(errno);
      return false;
    }
    bytes += sent;
    size -= static_cast<size_t>(sent);
    written_ += static_cast<uint64_t>(sent);
  }
  return true;
}

FILE* ByteStream::openFile() {
  cookie_io_functions_t functions = {};
  functions.write = [](void* self, const char* data, size_t size) -> ssize_t {
    return static_cast<ByteStream*>(self)->write(data, size) ? static_cast<ssize_t>(size) : -1;
  };
  return fopencookie(this, "w", functions);
}

}  // namespace wircam::recorder
