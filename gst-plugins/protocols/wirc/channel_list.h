// The text form of a value per channel, as users write it on a command line
// or in a property: 12 comma-separated numbers, or one for every channel
// ("20000", "1500,1500,1000,...").
#pragma once

#include <string>

#include "common/expected.h"
#include "wirc/messages.h"

namespace wircam::wirc {

Expected<ChannelValues, std::string> parseChannelList(const std::string& text);
std::string formatChannelList(const ChannelValues& values);

}  // namespace wircam::wirc
