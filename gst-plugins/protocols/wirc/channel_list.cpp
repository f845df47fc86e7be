#include "wirc/channel_list.h"

#include <charconv>
#include <vector>

namespace wircam::wirc {

Expected<ChannelValues, std::string> parseChannelList(const std::string& text) {
  std::vector<uint16_t> values;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    uint16_t value = 0;
    auto [last, error] = std::from_chars(text.data() + start, text.data() + end, value);
    if (error != std::errc() || last != text.data() + end)
      return unexpected("'" + text.substr(start, end - start) +
                        "' is not a number of 0..65535 (in '" + text + "')");
    values.push_back(value);
    start = end + 1;
  }
  if (values.size() != 1 && values.size() != kChannelCount)
    return unexpected("'" + text + "' has " + std::to_string(values.size()) +
                      " values: give 1 (for every channel) or 12");
  ChannelValues channels{};
  for (size_t i = 0; i < kChannelCount; ++i) channels[i] = values[values.size() == 1 ? 0 : i];
  return channels;
}

std::string formatChannelList(const ChannelValues& values) {
  std::string text;
  for (auto value : values) text += (text.empty() ? "" : ",") + std::to_string(value);
  return text;
}

}  // namespace wircam::wirc
