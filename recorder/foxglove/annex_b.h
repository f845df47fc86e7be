// H.264 as Foxglove decodes it (foxglove.CompressedVideo, format "h264"):
// Annex B, NAL units after start codes, each key frame led by its SPS and
// PPS. The recorder's H.264 is "avc" (what the muxers take): NAL units
// after their lengths, the parameter sets in the caps' codec_data.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace wircam::recorder {

class AnnexB {
 public:
  // From an "avc" stream's codec_data (an AVCDecoderConfigurationRecord,
  // ISO/IEC 14496-15 5.2.4.1); nullopt if it is not one.
  static std::optional<AnnexB> fromAvcC(std::string_view record);
  // One access unit of length-prefixed NAL units in Annex B; nullopt if a
  // length runs past its end.
  std::optional<std::string> convert(std::string_view accessUnit, bool keyFrame) const;

 private:
  std::string parameterSets_;  // the SPS and PPS, each after a start code
  size_t lengthSize_ = 4;
};

}  // namespace wircam::recorder
