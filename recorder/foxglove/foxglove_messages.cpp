#include "foxglove/foxglove_messages.h"

#include "foxglove/protobuf_wire.h"

namespace wircam::recorder {

extern const unsigned char kFoxgloveDescriptorSet[];
extern const std::size_t kFoxgloveDescriptorSet_size;

namespace {

// google.protobuf.Timestamp
std::string timestampOf(int64_t utcNs) {
  return ProtobufWriter()
      .varint(1, static_cast<uint64_t>(utcNs / 1000000000))
      .varint(2, static_cast<uint64_t>(utcNs % 1000000000))
      .out();
}

// foxglove.Color
std::string colorOf(double r, double g, double b, double a) {
  return ProtobufWriter().number(1, r).number(2, g).number(3, b).number(4, a).out();
}

// foxglove.Point2
std::string pointOf(double x, double y) { return ProtobufWriter().number(1, x).number(2, y).out(); }

// foxglove.Vector3 and foxglove.Quaternion
std::string vectorOf(double x, double y, double z) {
  return ProtobufWriter().number(1, x).number(2, y).number(3, z).out();
}
std::string quaternionOf(double x, double y, double z, double w) {
  return ProtobufWriter().number(1, x).number(2, y).number(3, z).number(4, w).out();
}

double numberIn(const nlohmann::json& value) { return value.is_number() ? value.get<double>() : 0; }

}  // namespace

std::string_view foxgloveDescriptorSet() {
  return {reinterpret_cast<const char*>(kFoxgloveDescriptorSet), kFoxgloveDescriptorSet_size};
}

std::string compressedImageHead(int64_t utcNs, const std::string& frameId,
                                const std::string& format, size_t dataBytes) {
  return ProtobufWriter()
      .bytes(1, timestampOf(utcNs))
      .bytes(4, frameId)
      .bytes(3, format)
      .lengthOnly(2, dataBytes)
      .out();
}

std::string compressedVideoHead(int64_t utcNs, const std::string& frameId,
                                const std::string& format, size_t dataBytes) {
  return ProtobufWriter()
      .bytes(1, timestampOf(utcNs))
      .bytes(2, frameId)
      .bytes(4, format)
      .lengthOnly(3, dataBytes)
      .out();
}

std::string imageAnnotationsOf(const nlohmann::json& line, int64_t utcNs) {
  constexpr uint64_t kLineLoop = 2;
  ProtobufWriter annotations;
  std::string stamp = timestampOf(utcNs);
  for (const auto& tag : line.value("detections", nlohmann::json::array())) {
    if (!tag.is_object()) continue;
    const auto& corners = tag.value("corners", nlohmann::json::array());
    if (!corners.is_array() || corners.size() != 8) continue;
    ProtobufWriter outline;  // foxglove.PointsAnnotation
    outline.bytes(1, stamp).varint(2, kLineLoop);
    for (size_t i = 0; i < 8; i += 2)
      outline.bytes(3, pointOf(numberIn(corners[i]), numberIn(corners[i + 1])));
    outline.bytes(4, colorOf(0.1, 0.9, 0.2, 1)).bytes(6, colorOf(0, 0, 0, 0)).number(7, 3);
    annotations.bytes(2, outline.out());
    ProtobufWriter label;  // foxglove.TextAnnotation
    label.bytes(1, stamp)
        .bytes(2, pointOf(numberIn(tag.value("cx", nlohmann::json())),
                          numberIn(tag.value("cy", nlohmann::json()))))
        .bytes(3, "tag " + std::to_string(tag.value("id", -1)))
        .number(4, 14)
        .bytes(5, colorOf(1, 1, 1, 1))
        .bytes(6, colorOf(0, 0, 0, 0.6));
    annotations.bytes(3, label.out());
  }
  annotations.bytes(5, stamp);
  return annotations.out();
}

std::string poseInFrameOf(double x, double y, double z, int64_t utcNs, const std::string& frameId) {
  // The identity rotation: an all-zero quaternion (protobuf's default) is none.
  std::string pose =
      ProtobufWriter().bytes(1, vectorOf(x, y, z)).bytes(2, quaternionOf(0, 0, 0, 1)).out();
  return ProtobufWriter().bytes(1, timestampOf(utcNs)).bytes(2, frameId).bytes(3, pose).out();
}

nlohmann::json foxgloveLog(const std::string& stream, const std::string& message, int64_t utcNs) {
  constexpr int kInfo = 2, kWarning = 3;
  bool bad = message.find("lost") != std::string::npos ||
             message.find("stale") != std::string::npos ||
             message.find("fail") != std::string::npos || message.find("gave") != std::string::npos;
  return {{"timestamp", {{"sec", utcNs / 1000000000}, {"nsec", utcNs % 1000000000}}},
          {"level", bad ? kWarning : kInfo},
          {"message", message},
          {"name", stream},
          {"file", ""},
          {"line", 0}};
}

}  // namespace wircam::recorder
