// What wirc-cli reads from its user: hex text, and JSON messages for
// `encode`. Neither crashes; a message the JSON reader accepts encodes,
// and decodes back to itself.
#include <cstdlib>
#include <string_view>

#include "hex.h"
#include "message_json.h"

using namespace wircam;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  auto bytes = cli::parseHex(text);
  if (bytes && bytes->size() * 2 > size) std::abort();
  auto json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) return 0;
  auto message = cli::fromJson(json);
  if (!message) return 0;
  auto frame = wirc::encode(*message);
  if (!frame) return 0;  // fromJson names fields; encode checks the values
  auto again = wirc::decode(*frame);
  if (!again || !(*again == *message)) std::abort();
  cli::toJson(*again);
  return 0;
}
