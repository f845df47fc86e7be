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

// set_property's and get_property's part for an element's `periods` and
// `failsafe` (ids `periodsId`, `failsafeId`; the settings' members of those
// names, and `given`); false for any other id.
template <typename Settings>
bool setLoginProperty(GObject* element, guint id, guint periodsId, guint failsafeId,
                      const GValue* value, Settings& s) {
  if (id != periodsId && id != failsafeId) return false;
  bool periods = id == periodsId;
  setChannelListProperty(element, periods ? "periods" : "failsafe", value,
                         periods ? s.periods : s.failsafe, s.given);
  return true;
}

template <typename Settings>
bool getLoginProperty(guint id, guint periodsId, guint failsafeId, GValue* value,
                      const Settings& s) {
  if (id != periodsId && id != failsafeId) return false;
  getChannelListProperty(value, id == periodsId ? s.periods : s.failsafe);
  return true;
}

}  // namespace wircam::gst
