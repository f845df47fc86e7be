#include "login_properties.h"

#include "wirc/channel_list.h"
#include "wirc/transmitter_session.h"

namespace wircam::gst {

void installLoginProperties(GObjectClass* klass, guint periodsId, guint failsafeId) {
  auto flags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                        GST_PARAM_MUTABLE_READY);
  g_object_class_install_property(
      klass, periodsId,
      g_param_spec_string("periods", "Channel periods",
                          "Servo pulse period per channel that the login sets (CCFG): 12 "
                          "comma-separated µs values, or one for all, 5000..20000, ch1/ch2, "
                          "ch3/ch4, ch5/ch6 equal. Only the first transmitter to log in "
                          "configures the device",
                          wirc::formatChannelList(wirc::SessionConfig{}.periods).c_str(), flags));
  g_object_class_install_property(
      klass, failsafeId,
      g_param_spec_string("failsafe", "Failsafe",
                          "What each channel does when the link is lost (FCFG): 12 "
                          "comma-separated values or one for all, 800..2200 µs, 0 = hold the "
                          "last pulse, 65535 = no pulse. Only the first transmitter to log in "
                          "configures the device",
                          wirc::formatChannelList(wirc::SessionConfig{}.failsafe).c_str(), flags));
}

void setChannelListProperty(GObject* element, const char* name, const GValue* value,
                            wirc::ChannelValues& target, std::set<std::string>& given) {
  const char* text = g_value_get_string(value);
  auto channels = wirc::parseChannelList(text ? text : "");
  std::optional<wirc::ProtocolError> refused;
  if (channels)
    refused = std::string(name) == "periods" ? wirc::validate(wirc::Ccfg{*channels})
                                             : wirc::validate(wirc::Fcfg{*channels});
  if (!channels || refused) {
    g_warning("%s: %s '%s' refused, kept '%s': %s", GST_OBJECT_NAME(element), name,
              text ? text : "", wirc::formatChannelList(target).c_str(),
              channels ? refused->message().c_str() : channels.error().c_str());
    return;
  }
  target = *channels;
  given.insert(name);
}

void getChannelListProperty(GValue* value, const wirc::ChannelValues& source) {
  g_value_set_string(value, wirc::formatChannelList(source).c_str());
}

}  // namespace wircam::gst
