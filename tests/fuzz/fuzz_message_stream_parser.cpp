// Feeds arbitrary bytes, cut into arbitrary reads, to the control-stream
// parser. Besides not crashing it checks that memory stays bounded and that
// every message it accepts survives encode → decode unchanged (but for a
// peer's text, which decode takes whatever it holds and encode may refuse).
#include <cstdlib>
#include <string_view>

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
    if (!frame) {
      std::string_view field = frame.error().field;
      if (field != "name" && field != "serial" && field != "ssid" && field != "password" &&
          field != "country")
        std::abort();  // decode accepted a value encode refuses
      return;
    }
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
