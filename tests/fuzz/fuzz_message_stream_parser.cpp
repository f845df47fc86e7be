// Feeds arbitrary bytes, cut into arbitrary reads, to the control-stream
// parser. Besides not crashing it checks that memory stays bounded and that
// every message it accepts survives encode → decode unchanged.
#include <cstdlib>

#include "wirc/message_stream_parser.h"

using namespace wircam::wirc;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  // The first byte picks the read size, so splits land everywhere.
  size_t chunk = data[0] % 64 + 1;
  std::span<const uint8_t> input(data + 1, size - 1);

  MessageStreamParser parser;
  auto check = [](const wircam::Expected<Message, ProtocolError>& result) {
    if (!result) return;
    auto frame = encode(*result);
    if (!frame) std::abort();  // decode accepted what encode refuses
    auto again = decode(*frame);
    if (!again || !(*again == *result)) std::abort();
  };
  while (!input.empty()) {
    size_t n = std::min(chunk, input.size());
    parser.feed(input.first(n), check);
    if (parser.pendingBytes() > kMaxFrameSize) std::abort();
    input = input.subspan(n);
  }
  return 0;
}
