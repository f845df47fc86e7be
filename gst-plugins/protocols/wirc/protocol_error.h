// What went wrong with a WiRC message, precise enough to name the field and to
// answer the sender with an ERR.
#pragma once

#include <cstdint>
#include <string>

namespace wircam::wirc {

enum class ErrorKind {
  BadCrc,          // checksum does not match: resync on the next AA BB
  UnknownCommand,  // valid frame, command code not in the spec
  BadLength,       // body length not the one the command requires
  InvalidField,    // a field breaks a rule of the spec (range, pairing, text)
};

struct ProtocolError {
  ErrorKind kind;
  uint8_t command = 0;  // command code of the offending message
  std::string field;    // e.g. "ch2 period"; empty when not about one field
  std::string detail;   // human-readable explanation

  // One line for logs and CLI output, e.g. "CCFG ch2 period: 4000 ...".
  std::string message() const;
};

const char* errorKindName(ErrorKind kind);

}  // namespace wircam::wirc
