#include "app/option_rows.h"

#include <glib.h>

#include "app/option_values.h"
#include "record/retention.h"
#include "wirc/channel_list.h"
#include "wirc/transmitter_session.h"

namespace wircam::recorder::option_rows {

Apply seconds(double RecorderOptions::*field, double low, double high) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto s = number(value);
    if (!s || *s < low || *s > high) {
      char range[64];
      g_snprintf(range, sizeof range, "seconds, %g..%g", low, high);
      return range;
    }
    o.*field = *s;
    return std::nullopt;
  };
}

Apply wholeNumber(unsigned RecorderOptions::*field, double low, double high, const char* unit) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto n = wholeWithin(value, low, high);
    if (!n) {
      char range[64];
      g_snprintf(range, sizeof range, "%s%s%g..%g", unit, *unit ? ", " : "", low, high);
      return range;
    }
    o.*field = static_cast<unsigned>(*n);
    return std::nullopt;
  };
}

Apply onOff(bool RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    std::string on = value;
    if (on != "on" && on != "off") return "on or off";
    o.*field = on == "on";
    return std::nullopt;
  };
}

Apply text(std::string RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    o.*field = value;
    return std::nullopt;
  };
}

Apply optionalText(std::optional<std::string> RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    o.*field = value;
    return std::nullopt;
  };
}

Apply serverAddress(std::optional<ServerAddress> RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto address = parseServerAddress(value);
    if (!address) return "[HOST]:PORT, as in :8080 or 127.0.0.1:8080";
    o.*field = *address;
    return std::nullopt;
  };
}

Apply size(uint64_t RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto bytes = byteSize(value);
    if (!bytes) return "a size like 500M or 20G";
    o.*field = *bytes;
    return std::nullopt;
  };
}

Apply duration(std::chrono::seconds RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto d = parseDuration(value);
    if (!d || d->count() == 0) return "a duration like 7d, 12h, 30m or 90s";
    o.*field = *d;
    return std::nullopt;
  };
}

Apply channels(std::optional<std::string> RecorderOptions::*field, bool periods) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto list = wirc::parseChannelList(value);
    if (!list) return list.error();
    auto invalid = periods ? wirc::validate(wirc::Ccfg{*list}) : wirc::validate(wirc::Fcfg{*list});
    if (invalid) return invalid->message();
    // The login's own values written out are no setting: the cameras'
    // pipelines stay as they were (a reload restarts no camera for them).
    if (*list == (periods ? wirc::SessionConfig{}.periods : wirc::SessionConfig{}.failsafe))
      o.*field = std::nullopt;
    else
      o.*field = value;
    return std::nullopt;
  };
}

OptionProblem topicPrefix(const std::string& prefix, const char* example) {
  if (prefix.empty() || prefix.find_first_of("+# ") != std::string::npos || prefix.front() == '/' ||
      prefix.back() == '/')
    return std::string("a topic prefix without + # or a leading or trailing /, like ") + example;
  return std::nullopt;
}

OptionProblem commandLine(RecorderOptions& o, const char* value) {
  gchar** argv = nullptr;
  GError* error = nullptr;
  if (!g_shell_parse_argv(value, nullptr, &argv, &error)) {
    std::string problem = error->message;
    g_error_free(error);
    return "cannot split the command: " + problem;
  }
  o.onSegmentClosed.assign(argv, argv + g_strv_length(argv));
  g_strfreev(argv);
  return std::nullopt;
}

std::optional<bool> trueOrFalse(const char* value) {
  std::string v = value;
  if (v == "true" || v == "1") return true;
  if (v == "false" || v == "0") return false;
  return std::nullopt;
}

}  // namespace wircam::recorder::option_rows
