#include "app/recorder_options.h"

#include <getopt.h>
#include <glib.h>

#include <algorithm>
#include <memory>

#include "app/option_table.h"
#include "app/option_values.h"
#include "fleet/mqtt_url.h"

namespace wircam::recorder {

const char* extensionOf(Container container) {
  return container == Container::kMp4 ? ".mp4" : ".mkv";
}

namespace {

// Applies one option given by its name (from the command line or the
// config file's [recorder] group), and keeps its value as given.
std::optional<std::string> applyOption(RecorderOptions& o, const OptionSpec& spec,
                                       const char* value) {
  if (auto problem = spec.apply(o, value)) return problem;
  o.given[spec.name].push_back(value);
  return std::nullopt;
}

using KeyFile = std::unique_ptr<GKeyFile, decltype(&g_key_file_free)>;
using Strings = std::unique_ptr<gchar*, decltype(&g_strfreev)>;

std::string keyValue(GKeyFile* file, const std::string& group, const std::string& key) {
  gchar* text = g_key_file_get_string(file, group.c_str(), key.c_str(), nullptr);
  std::string out = text ? text : "";
  g_free(text);
  return out;
}

Expected<DeviceTarget, std::string> readDevice(GKeyFile* file, const std::string& group,
                                               const std::string& where) {
  DeviceTarget device;
  device.label = group.substr(7);
  if (device.label.find_first_not_of(" \t") == std::string::npos)
    return unexpected(where + " [" + group +
                      "] needs a name: [device NAME], NAME starting the stream's (NAME-cam0)");
  Strings keys(g_key_file_get_keys(file, group.c_str(), nullptr, nullptr), g_strfreev);
  for (gchar** key = keys.get(); key && *key; ++key) {
    const auto& table = deviceKeyTable();
    auto spec = std::find_if(table.begin(), table.end(),
                             [&](const DeviceKeySpec& s) { return *key == std::string(s.key); });
    std::string at = where + " [" + group + "] " + *key;
    if (spec == table.end()) {
      std::string known;
      for (const auto& s : table) known += (known.empty() ? "" : ", ") + std::string(s.key);
      return unexpected(at + ": unknown key (" + known + ")");
    }
    // A device's own key, or an option it overrides (cameras, follow, ...).
    if (auto problem = spec->apply(device, keyValue(file, group, *key)))
      return unexpected(at + ": " + *problem);
  }
  if (device.host.empty()) return unexpected(where + " [" + group + "] needs host");
  return device;
}

std::optional<std::string> loadConfig(const char* path, RecorderOptions& o) {
  // Not a FIFO or a device: reading one would wait for a writer, and a
  // reload reads on the main loop.
  if (!g_file_test(path, G_FILE_TEST_IS_REGULAR))
    return std::string("cannot read --config ") + path +
           (g_file_test(path, G_FILE_TEST_EXISTS) ? ": not a regular file" : ": no such file");
  KeyFile file(g_key_file_new(), g_key_file_free);
  GError* error = nullptr;
  if (!g_key_file_load_from_file(file.get(), path, G_KEY_FILE_NONE, &error)) {
    std::string message = std::string("cannot read --config ") + path + ": " + error->message;
    g_error_free(error);
    return message;
  }
  Strings groups(g_key_file_get_groups(file.get(), nullptr), g_strfreev);
  for (gchar** g = groups.get(); *g; ++g) {
    std::string group = *g;
    if (group == "recorder") {
      Strings keys(g_key_file_get_keys(file.get(), "recorder", nullptr, nullptr), g_strfreev);
      for (gchar** key = keys.get(); key && *key; ++key) {
        const OptionSpec* spec = findOption(*key);
        std::string where = std::string(path) + " [recorder] " + *key;
        if (!spec || spec->commandLineOnly)
          return where + ": not an option (wirc-recorder --help lists them)";
        if (auto problem = applyOption(o, *spec, keyValue(file.get(), group, *key).c_str()))
          return where + ": " + *problem;
      }
    } else if (group.rfind("device ", 0) == 0) {
      auto device = readDevice(file.get(), group, path);
      if (!device) return device.error();
      o.devices.push_back(std::move(*device));
    } else {
      return std::string(path) + ": unknown group [" + group + "] ([recorder] or [device NAME])";
    }
  }
  return std::nullopt;
}

// What no single option can say: the ones that go together, and the
// devices resolved against the recorder-wide options.
std::optional<std::string> checkTogether(RecorderOptions& o) {
  if (o.outDir.empty()) return std::string("--out DIR (or out= in the config) is needed");
  if (o.follow && o.detectFamily.empty()) return std::string("--follow needs --detect FAMILY");
  if (o.mqttDiscovery && !o.mqtt)
    return std::string("--mqtt-discovery publishes to the MQTT broker: it needs --mqtt URL");
  if ((o.fleet || !o.fleetUrl.empty()) && (!o.mqtt || !o.http))
    return std::string(o.fleet ? "--fleet" : "--fleet-url") +
           " works over the broker and the web server: it needs --mqtt URL and --http [HOST]:PORT";
  if (!o.mqttCaFile.empty() && (!o.mqtt || !parseMqttUrl(*o.mqtt)->tls))
    return std::string("--mqtt-cafile is for a TLS broker: --mqtt mqtts://HOST[:PORT]");
  if (o.httpCert.empty() != o.httpKey.empty())
    return std::string("--http-cert and --http-key go together: the certificate and its key");
  if (!o.httpCert.empty() && !o.http && !o.foxglove)
    return std::string("--http-cert needs --http [HOST]:PORT (or --foxglove)");
  if (o.keepEvents.count() > 0 && o.keepEvents <= o.maxAge)
    return std::string(
        "--keep-events keeps segments with events longer than --max-age: give "
        "--max-age and a longer --keep-events");
  if (!o.followTuning.empty() && !o.follow)
    return std::string("--follow-tuning tunes the follower: it needs --follow");
  if (o.container == Container::kMp4 && o.codec == Codec::kJpeg)
    return std::string(
        "--format mp4 needs --codec h264: GStreamer's mp4mux cannot carry the camera's JPEG "
        "frames as they are (use mkv to keep them untouched)");
  if (o.http && o.httpToken.empty() && !o.http->host.empty() && o.http->host != "127.0.0.1" &&
      o.http->host != "localhost")
    return std::string("--http " + o.http->host + ":" + std::to_string(o.http->port) +
                       " would open the recorder beyond this machine without authentication: "
                       "give --http-token T (or leave HOST out for 127.0.0.1 only)");
  if (o.foxglove && o.httpToken.empty() && !o.foxglove->host.empty() &&
      o.foxglove->host != "127.0.0.1" && o.foxglove->host != "localhost")
    return std::string("--foxglove " + o.foxglove->host + ":" + std::to_string(o.foxglove->port) +
                       " would open the recorder beyond this machine without authentication: "
                       "give --http-token T (or leave HOST out for 127.0.0.1 only)");
  if (o.devices.empty()) o.devices.push_back({"", 1984, "discovered"});
  if (o.cameras.empty()) o.cameras.push_back(0);
  for (auto& device : o.devices) {
    if (device.cameras.empty()) device.cameras = o.cameras;
    if (!device.follow) device.follow = o.follow;
    if (device.control && !*device.follow)
      return std::string("device " + device.label +
                         " has control=, which steers only with follow (--follow or follow=true)");
    if (*device.follow && o.detectFamily.empty())
      return std::string("device " + device.label + " follows, which needs detect=FAMILY");
    auto positions = positionSource(device.marvelmind ? device.marvelmind : o.marvelmind,
                                    device.beacons ? device.beacons : o.beacons);
    if (!positions) return std::string("device " + device.label + ": " + positions.error());
    device.positions = *positions;
  }
  return std::nullopt;
}

}  // namespace

Expected<RecorderOptions, std::string> parseOptions(int argc, char** argv) {
  std::vector<option> options;
  for (const auto& spec : optionTable()) {
    int argument = !spec.value          ? no_argument
                   : spec.optionalValue ? optional_argument
                                        : required_argument;
    options.push_back({spec.name, argument, nullptr, 0});
  }
  options.push_back({nullptr, 0, nullptr, 0});
  RecorderOptions o;
  o.outDir.clear();
  optind = 1;
  opterr = 0;  // (getopt's own message, then ours, said it twice)
  int opt, index = 0;
  while ((opt = getopt_long(argc, argv, ":h", options.data(), &index)) != -1) {
    if (opt == 'h') return unexpected("help");
    // The word getopt stopped at: the option without its value, or unknown.
    std::string given = argv[optind - 1];
    if (opt == ':') return unexpected(given + " needs a value");
    if (opt != 0) return unexpected("unknown option " + given);
    const OptionSpec& spec = optionTable()[index];
    std::string name = spec.name;
    if (name == "help") return unexpected("help");
    if (name == "config") {
      o.configFile = optarg;
      if (auto problem = loadConfig(optarg, o)) return unexpected(*problem);
      continue;
    }
    // "--mqtt-discovery [PREFIX]": the prefix may follow as a word of its
    // own (getopt takes an optional value only after "=").
    if (options[index].has_arg == optional_argument && !optarg && optind < argc &&
        argv[optind][0] != '-')
      optarg = argv[optind++];
    if (auto problem = applyOption(o, spec, optarg ? optarg : "true"))
      return unexpected(name == "device" ? *problem : "--" + name + ": " + *problem);
  }
  if (optind < argc) return unexpected(std::string("unexpected argument '") + argv[optind] + "'");
  if (auto problem = checkTogether(o)) return unexpected(*problem);
  return o;
}

std::optional<std::string> reloadRefusal(const RecorderOptions& running,
                                         const RecorderOptions& reread) {
  // An option's effect, alone: its values (none: its default) applied to
  // the defaults. Given or not, written twice or once, the same effect is
  // no change.
  auto effectOf = [](const OptionSpec& spec, const RecorderOptions& options) {
    RecorderOptions alone;
    auto values = options.given.find(spec.name);
    if (values != options.given.end())
      for (const auto& value : values->second) spec.apply(alone, value.c_str());
    return alone;
  };
  for (const auto& spec : optionTable()) {
    if (spec.reloadable || spec.commandLineOnly) continue;
    if (!(effectOf(spec, running) == effectOf(spec, reread)))
      return std::string(spec.name) +
             " changed, which takes a restart of the recorder (a reload changes the devices, "
             "cameras, files, detection and retention)";
  }
  return std::nullopt;
}

}  // namespace wircam::recorder
