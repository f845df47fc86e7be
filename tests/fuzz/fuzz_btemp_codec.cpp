// BTEMP datagrams through decode(): nothing crashes, and every message it
// accepts (but the opaque video segments) encodes to a datagram that
// decodes to the same message.
#include <cstdlib>

#include "btemp/btemp_messages.h"

using namespace wircam::btemp;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto message = decode({data, size});
  if (!message || std::holds_alternative<VideoSegment>(*message)) return 0;
  auto again = decode(encode(*message));
  if (!again || !(*again == *message)) std::abort();
  return 0;
}
