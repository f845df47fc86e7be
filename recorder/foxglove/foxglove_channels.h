// The channels a camera STREAM is seen on in Foxglove (and Lichtblick), the
// same live (the Foxglove WebSocket) as in an MCAP export, so that a layout
// made on a recording works on the vehicle:
//   /STREAM/image      foxglove.CompressedImage (protobuf): the camera's JPEG;
//                      or foxglove.CompressedVideo: the recording's H.264
//   /STREAM/tags       foxglove.ImageAnnotations (protobuf): each tag's outline and id
//   /STREAM/telemetry  wircam.Telemetry (JSON): sidecar lines; live, the status each second
//   /STREAM/log        foxglove.Log (JSON): the session's events
//   /STREAM/pose       foxglove.PoseInFrame (protobuf): the Marvelmind position
#pragma once

#include <string>
#include <vector>

namespace wircam::recorder {

enum class FoxgloveTopic { Image, Tags, Telemetry, Log, Pose };

struct FoxgloveChannel {
  FoxgloveTopic topic;
  std::string suffix;          // "/image": the topic is "/" + STREAM + suffix
  std::string encoding;        // of the messages: "protobuf" or "json"
  std::string schemaName;      // "foxglove.CompressedImage", ...
  std::string schemaEncoding;  // "protobuf" or "jsonschema"
  std::string schema;          // a FileDescriptorSet's bytes, or a JSON schema's text
  bool compressible;           // worth zstd in an MCAP chunk (not JPEG or H.264)
};

struct FoxgloveChannelSet {
  bool video = false;      // images as H.264 (CompressedVideo), not JPEG
  bool positions = false;  // a pose channel
};
// A camera's channels.
std::vector<FoxgloveChannel> foxgloveChannels(FoxgloveChannelSet set);

// "/STREAM/image"
std::string foxgloveTopicName(const std::string& stream, const FoxgloveChannel& channel);

}  // namespace wircam::recorder
