// A single datagram (PSD, BCSA, PCD...) through decode(): what it accepts
// encodes again, unless a peer's text (which decode takes whatever it
// holds) is more than encode allows; then it is refused by name.
#include <cstdlib>
#include <string_view>

#include "wirc/messages.h"

using namespace wircam::wirc;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto message = decode({data, size});
  if (!message) return 0;
  auto frame = encode(*message);
  if (!frame) {
    std::string_view field = frame.error().field;
    bool text = field == "name" || field == "serial" || field == "ssid" || field == "password" ||
                field == "country";
    if (!text) std::abort();  // decode accepted a value encode refuses
    return 0;
  }
  auto again = decode(*frame);
  if (!again || !(*again == *message)) std::abort();
  return 0;
}
