#include "export/mcap_export.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "gst_scoped.h"

namespace wircam::recorder {

namespace {

// JSON schemas of Foxglove's message types, from their documented fields.
nlohmann::json timeSchema() {
  return {{"type", "object"},
          {"title", "time"},
          {"properties",
           {{"sec", {{"type", "integer"}, {"minimum", 0}}},
            {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}}};
}

nlohmann::json colorSchema() {
  nlohmann::json channel = {{"type", "number"}, {"minimum", 0}, {"maximum", 1}};
  return {{"type", "object"},
          {"title", "foxglove.Color"},
          {"properties", {{"r", channel}, {"g", channel}, {"b", channel}, {"a", channel}}}};
}

nlohmann::json point2Schema() {
  return {{"type", "object"},
          {"title", "foxglove.Point2"},
          {"properties", {{"x", {{"type", "number"}}}, {"y", {{"type", "number"}}}}}};
}

nlohmann::json compressedImageSchema() {
  return {{"title", "foxglove.CompressedImage"},
          {"type", "object"},
          {"properties",
           {{"timestamp", timeSchema()},
            {"frame_id", {{"type", "string"}}},
            {"data", {{"type", "string"}, {"contentEncoding", "base64"}}},
            {"format", {{"type", "string"}}}}}};
}

nlohmann::json imageAnnotationsSchema() {
  nlohmann::json points = {{"type", "object"},
                           {"title", "foxglove.PointsAnnotation"},
                           {"properties",
                            {{"timestamp", timeSchema()},
                             {"type", {{"type", "integer"}, {"enum", {0, 1, 2, 3, 4}}}},
                             {"points", {{"type", "array"}, {"items", point2Schema()}}},
                             {"outline_color", colorSchema()},
                             {"outline_colors", {{"type", "array"}, {"items", colorSchema()}}},
                             {"fill_color", colorSchema()},
                             {"thickness", {{"type", "number"}, {"minimum", 0}}}}}};
  nlohmann::json texts = {{"type", "object"},
                          {"title", "foxglove.TextAnnotation"},
                          {"properties",
                           {{"timestamp", timeSchema()},
                            {"position", point2Schema()},
                            {"text", {{"type", "string"}}},
                            {"font_size", {{"type", "number"}, {"minimum", 0}}},
                            {"text_color", colorSchema()},
                            {"background_color", colorSchema()}}}};
  return {{"title", "foxglove.ImageAnnotations"},
          {"type", "object"},
          {"properties",
           {{"circles", {{"type", "array"}, {"items", {{"type", "object"}}}}},
            {"points", {{"type", "array"}, {"items", points}}},
            {"texts", {{"type", "array"}, {"items", texts}}}}}};
}

nlohmann::json logSchema() {
  return {{"title", "foxglove.Log"},
          {"type", "object"},
          {"properties",
           {{"timestamp", timeSchema()},
            {"level", {{"type", "integer"}, {"enum", {0, 1, 2, 3, 4, 5}}}},
            {"message", {{"type", "string"}}},
            {"name", {{"type", "string"}}},
            {"file", {{"type", "string"}}},
            {"line", {{"type", "integer"}, {"minimum", 0}}}}}};
}

nlohmann::json telemetrySchema() {
  return {{"title", "wircam.Telemetry"},
          {"description",
           "One line of a recording's telemetry sidecar: battery, link and stream statistics, "
           "detections, control commands, session events, positions (README: the sidecar)"},
          {"type", "object"},
          {"properties",
           {{"type", {{"type", "string"}}},
            {"pts", {{"type", "integer"}, {"description", "ns on the export's timeline"}}},
            {"utc", {{"type", "string"}}}}},
          {"required", {"type", "utc"}}};
}

nlohmann::json timeOf(int64_t utcNs) {
  return {{"sec", utcNs / 1000000000}, {"nsec", utcNs % 1000000000}};
}

nlohmann::json color(double r, double g, double b, double a) {
  return {{"r", r}, {"g", g}, {"b", b}, {"a", a}};
}

// A detections line's tags as outlines with their ids beside.
nlohmann::json annotationsOf(const nlohmann::json& line, int64_t utcNs) {
  nlohmann::json outlines = nlohmann::json::array(), labels = nlohmann::json::array();
  for (const auto& tag : line.value("detections", nlohmann::json::array())) {
    const auto& corners = tag.value("corners", nlohmann::json::array());
    if (!corners.is_array() || corners.size() != 8) continue;
    nlohmann::json points = nlohmann::json::array();
    for (size_t i = 0; i < 8; i += 2) points.push_back({{"x", corners[i]}, {"y", corners[i + 1]}});
    outlines.push_back({{"timestamp", timeOf(utcNs)},
                        {"type", 2},  // LINE_LOOP
                        {"points", points},
                        {"outline_color", color(0.1, 0.9, 0.2, 1)},
                        {"outline_colors", nlohmann::json::array()},
                        {"fill_color", color(0, 0, 0, 0)},
                        {"thickness", 3}});
    labels.push_back({{"timestamp", timeOf(utcNs)},
                      {"position", {{"x", tag.value("cx", 0.0)}, {"y", tag.value("cy", 0.0)}}},
                      {"text", "tag " + std::to_string(tag.value("id", -1))},
                      {"font_size", 14},
                      {"text_color", color(1, 1, 1, 1)},
                      {"background_color", color(0, 0, 0, 0.6)}});
  }
  return {{"circles", nlohmann::json::array()}, {"points", outlines}, {"texts", labels}};
}

}  // namespace

McapExport::McapExport(std::string path, std::string stream)
    : path_(std::move(path)), stream_(std::move(stream)) {}

std::optional<std::string> McapExport::start(GstCaps* caps) {
  std::string media = gst_structure_get_name(gst_caps_get_structure(caps, 0));
  format_ = media == "video/x-h264" ? "h264" : "jpeg";
  auto writer = McapWriter::create(path_);
  if (!writer) return writer.error();
  writer_ = std::move(*writer);
  auto channel = [&](const char* topic, const std::string& schema, const nlohmann::json& json) {
    uint16_t id = writer_->addSchema(schema, "jsonschema", json.dump());
    return writer_->addChannel(id, "/" + stream_ + topic, "json");
  };
  image_ = channel("/image", "foxglove.CompressedImage", compressedImageSchema());
  tags_ = channel("/tags", "foxglove.ImageAnnotations", imageAnnotationsSchema());
  telemetry_ = channel("/telemetry", "wircam.Telemetry", telemetrySchema());
  log_ = channel("/log", "foxglove.Log", logSchema());
  return std::nullopt;
}

std::optional<std::string> McapExport::frame(GstBuffer* buffer, int64_t, int64_t utcNs, bool) {
  gst::ScopedBufferMap map(buffer, GST_MAP_READ);
  if (!map) return "an unreadable frame";
  // The JSON is built around the base64 text, which needs no escaping:
  // nlohmann's dump would look at each of its characters (a quarter of an
  // export's time).
  std::string message = nlohmann::json{
      {"timestamp", timeOf(utcNs)},
      {"frame_id", stream_},
      {"format", format_}}.dump();
  message.pop_back();  // the closing brace
  message += ",\"data\":\"";
  size_t head = message.size();
  message.resize(head + (map.size() / 3 + 1) * 4 + 4);
  gint state = 0, save = 0;
  char* out = message.data() + head;
  gsize written = g_base64_encode_step(map.data(), map.size(), FALSE, out, &state, &save);
  written += g_base64_encode_close(FALSE, out + written, &state, &save);
  message.resize(head + written);
  message += "\"}";
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  writer_->write(image_, time, time, message);
  return std::nullopt;
}

std::optional<std::string> McapExport::line(const nlohmann::json& line, int64_t, int64_t utcNs) {
  write(telemetry_, utcNs, line);
  std::string type = line.value("type", "");
  if (type == "detections") write(tags_, utcNs, annotationsOf(line, utcNs));
  if (type == "session" || (type == "vehicle" && line.contains("event"))) {
    std::string message = line.value("event", type);
    int level = message.find("lost") != std::string::npos ? 3 : 2;  // WARNING, INFO
    write(log_, utcNs,
          {{"timestamp", timeOf(utcNs)},
           {"level", level},
           {"message", message},
           {"name", stream_},
           {"file", ""},
           {"line", 0}});
  }
  return std::nullopt;
}

std::optional<std::string> McapExport::finish() {
  if (!writer_->finish()) return "cannot write " + path_ + ": " + std::strerror(errno);
  return std::nullopt;
}

void McapExport::write(uint16_t channel, int64_t utcNs, const nlohmann::json& message) {
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  writer_->write(channel, time, time, message.dump());
}

}  // namespace wircam::recorder
