#include "export/mcap_export.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "export/foxglove_messages.h"
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
           "detections, control commands, session events, positions (docs/recorder.md, \"What it "
           "writes\")"},
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

}  // namespace

McapExport::McapExport(std::string path, std::string stream)
    : path_(std::move(path)), stream_(std::move(stream)) {}

std::optional<std::string> McapExport::start(GstCaps* caps) {
  std::string media = gst_structure_get_name(gst_caps_get_structure(caps, 0));
  format_ = media == "video/x-h264" ? "h264" : "jpeg";
  auto writer = McapWriter::create(path_);
  if (!writer) return writer.error();
  writer_ = std::move(*writer);
  auto jsonChannel = [&](const char* topic, const std::string& schema, const nlohmann::json& json) {
    uint16_t id = writer_->addSchema(schema, "jsonschema", json.dump());
    return writer_->addChannel(id, "/" + stream_ + topic, "json");
  };
  std::string descriptors(foxgloveDescriptorSet());
  image_ =
      writer_->addChannel(writer_->addSchema("foxglove.CompressedImage", "protobuf", descriptors),
                          "/" + stream_ + "/image", "protobuf", false);
  tags_ =
      writer_->addChannel(writer_->addSchema("foxglove.ImageAnnotations", "protobuf", descriptors),
                          "/" + stream_ + "/tags", "protobuf");
  telemetry_ = jsonChannel("/telemetry", "wircam.Telemetry", telemetrySchema());
  log_ = jsonChannel("/log", "foxglove.Log", logSchema());
  return std::nullopt;
}

std::optional<std::string> McapExport::frame(GstBuffer* buffer, int64_t, int64_t utcNs, bool) {
  gst::ScopedBufferMap map(buffer, GST_MAP_READ);
  if (!map) return "an unreadable frame";
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  // The message's fields, then the frame's bytes as they are.
  writer_->write(image_, time, time, compressedImageHead(utcNs, stream_, format_, map.size()),
                 {reinterpret_cast<const char*>(map.data()), map.size()});
  return std::nullopt;
}

std::optional<std::string> McapExport::line(const nlohmann::json& line, int64_t, int64_t utcNs) {
  auto time = static_cast<uint64_t>(std::max<int64_t>(utcNs, 0));
  write(telemetry_, utcNs, line);
  std::string type = line.value("type", "");
  if (type == "detections") writer_->write(tags_, time, time, imageAnnotationsOf(line, utcNs));
  // Events, not the vehicle's status reports (twice a second: telemetry).
  bool vehicleEvent = type == "vehicle" && line.contains("event") && line["event"] != "status";
  if (type == "session" || vehicleEvent) {
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
