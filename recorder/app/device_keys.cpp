// The [device NAME] keys: a device's host, port, cameras and steering
// target, and the options it overrides.
#include <glib.h>

#include <memory>

#include "app/option_rows.h"
#include "app/option_values.h"

namespace wircam::recorder::option_rows {

std::vector<DeviceKeySpec> deviceKeyRows() {
  return {
      {.key = "host",
       .value = "HOST",
       .help = "its address (needed)",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.host = value;
         return std::nullopt;
       }},
      {.key = "port",
       .value = "PORT",
       .help = "its port (1984)",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto port = wholeWithin(value.c_str(), 1, 65535);
         if (!port) return "a port is 1..65535";
         d.port = static_cast<uint16_t>(*port);
         return std::nullopt;
       }},
      {.key = "cameras",
       .value = "N;N...",
       .help = "its cameras, instead of `--camera`'s",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.cameras.clear();
         std::unique_ptr<gchar*, decltype(&g_strfreev)> items(
             g_strsplit_set(value.c_str(), ";,", -1), g_strfreev);
         for (gchar** item = items.get(); *item; ++item) {
           if (!**item) continue;  // "0;1;"
           auto camera = wholeWithin(*item, 0, 255);
           if (!camera) return "cameras 0..255, as in 0;1";
           d.cameras.push_back(static_cast<int>(*camera));
         }
         if (d.cameras.empty()) return "a list like 0;1";
         return std::nullopt;
       }},
      {.key = "follow",
       .value = "true|false",
       .help = "whether it follows, instead of `--follow`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto on = trueOrFalse(value.c_str());
         if (!on) return "true or false";
         d.follow = *on;
         return std::nullopt;
       }},
      {.key = "control",
       .value = "URI",
       .help = "steer `rcoip://H:P`, `btemp://H:P` or `wirc://H:P` instead of this device, as "
               "`--device`'s `control=`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto control = parseControlTarget(value);
         if (!control) return control.error();
         d.control = *control;
         return std::nullopt;
       }},
      {.key = "marvelmind",
       .value = "HOST[:PORT]",
       .help = "its Marvelmind dashboard, instead of `--marvelmind`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.marvelmind = value;
         return std::nullopt;
       }},
      {.key = "beacon",
       .value = "ADDR[,ADDR]",
       .help = "its beacon(s), instead of `--beacon`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.beacons = value;
         return std::nullopt;
       }},
  };
}

}  // namespace wircam::recorder::option_rows
