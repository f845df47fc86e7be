#include "foxglove/foxglove_channels.h"

#include <nlohmann/json.hpp>

#include "foxglove/foxglove_messages.h"

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
           "One line of a recording's telemetry sidecar (battery, link and stream statistics, "
           "detections, control commands, session events, positions), or live the camera's "
           "status each second, type \"status\" (docs/recorder.md, \"What it writes\"; "
           "docs/foxglove.md)"},
          {"type", "object"},
          {"properties",
           {{"type", {{"type", "string"}}},
            {"pts", {{"type", "integer"}, {"description", "ns on the export's timeline"}}},
            {"utc", {{"type", "string"}}}}},
          {"required", {"type", "utc"}}};
}

}  // namespace

std::vector<FoxgloveChannel> foxgloveChannels(FoxgloveChannelSet set) {
  std::string descriptors(foxgloveDescriptorSet());
  // Foxglove shows JPEG as an image, and H.264 only as video.
  std::string image = set.video ? "foxglove.CompressedVideo" : "foxglove.CompressedImage";
  std::vector<FoxgloveChannel> channels = {
      {FoxgloveTopic::Image, "/image", "protobuf", image, "protobuf", descriptors, false},
      {FoxgloveTopic::Tags, "/tags", "protobuf", "foxglove.ImageAnnotations", "protobuf",
       descriptors, true},
      {FoxgloveTopic::Telemetry, "/telemetry", "json", "wircam.Telemetry", "jsonschema",
       telemetrySchema().dump(), true},
      {FoxgloveTopic::Log, "/log", "json", "foxglove.Log", "jsonschema", logSchema().dump(), true},
  };
  if (set.positions)
    channels.push_back({FoxgloveTopic::Pose, "/pose", "protobuf", "foxglove.PoseInFrame",
                        "protobuf", descriptors, true});
  return channels;
}

std::string foxgloveTopicName(const std::string& stream, const FoxgloveChannel& channel) {
  return "/" + stream + channel.suffix;
}

}  // namespace wircam::recorder
