#include "record/recording_query.h"

#include <glib.h>

#include <cstdio>

namespace wircam::recorder {

namespace {

constexpr int64_t kDayMs = 24 * 3600 * 1000;

std::string escaped(const std::string& value) {
  gchar* text = g_uri_escape_string(value.c_str(), nullptr, FALSE);
  std::string result = text;
  g_free(text);
  return result;
}

}  // namespace

std::optional<int64_t> unixMsOfUtc(const std::string& iso) {
  GDateTime* time = g_date_time_new_from_iso8601(iso.c_str(), nullptr);
  if (!time) return std::nullopt;
  int64_t ms = g_date_time_to_unix(time) * 1000 + g_date_time_get_microsecond(time) / 1000;
  g_date_time_unref(time);
  return ms;
}

Expected<RecordingQuery, std::string> recordingQueryOf(const char* camera, const char* vehicle,
                                                       const char* day) {
  RecordingQuery query{.camera = camera ? camera : "", .vehicle = vehicle ? vehicle : ""};
  if (day && *day) {
    int year = 0, month = 0, date = 0;
    char end = 0;
    auto midnight = std::sscanf(day, "%4d-%2d-%2d%c", &year, &month, &date, &end) == 3
                        ? unixMsOfUtc(std::string(day) + "T00:00:00Z")
                        : std::nullopt;
    if (!midnight)
      return unexpected("day '" + std::string(day) + "' is not a date: YYYY-MM-DD (UTC)");
    query.dayStartUnixMs = *midnight;
  }
  return query;
}

std::string queryString(const RecordingQuery& query) {
  std::string text;
  auto add = [&](const char* key, const std::string& value) {
    if (value.empty()) return;
    text += (text.empty() ? "?" : "&") + std::string(key) + "=" + escaped(value);
  };
  add("camera", query.camera);
  add("vehicle", query.vehicle);
  if (query.dayStartUnixMs) {
    GDateTime* time = g_date_time_new_from_unix_utc(*query.dayStartUnixMs / 1000);
    gchar* day = g_date_time_format(time, "%Y-%m-%d");
    add("day", day);
    g_free(day);
    g_date_time_unref(time);
  }
  return text;
}

bool matches(const RecordingQuery& query, const nlohmann::json& entry) {
  if (!entry.is_object()) return false;
  if (!query.camera.empty() && entry.value("camera", "") != query.camera) return false;
  if (!query.vehicle.empty()) {
    auto vehicle = entry.find("vehicle");
    if (vehicle == entry.end() || !vehicle->is_object() ||
        (vehicle->value("serial", "") != query.vehicle &&
         vehicle->value("name", "") != query.vehicle))
      return false;
  }
  if (query.dayStartUnixMs) {
    auto start = unixMsOfUtc(entry.value("start_utc", ""));
    if (!start) return false;
    auto end = *start + static_cast<int64_t>(entry.value("duration_s", 0.0) * 1000);
    if (end < *query.dayStartUnixMs || *start >= *query.dayStartUnixMs + kDayMs) return false;
  }
  return true;
}

}  // namespace wircam::recorder
