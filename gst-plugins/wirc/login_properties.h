// The properties by which wircsrc and wirccontrol say what the login
// configures on the device (CCFG periods, FCFG failsafe), as channel lists.
// Only the first transmitter to log in configures the device.
#pragma once

#include <gst/gst.h>

#include <set>
#include <string>

#include "wirc/messages.h"

namespace wircam::gst {

void installLoginProperties(GObjectClass* klass, guint periodsId, guint failsafeId);

// Takes a new list for `name` ("periods" or "failsafe") into `target` and
// marks it given; a list the device would refuse is refused here with a
// warning naming the element and the problem, keeping the old value.
void setChannelListProperty(GObject* element, const char* name, const GValue* value,
                            wirc::ChannelValues& target, std::set<std::string>& given);
void getChannelListProperty(GValue* value, const wirc::ChannelValues& source);

}  // namespace wircam::gst
