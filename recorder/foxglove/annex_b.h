// H.264 as Foxglove decodes it (foxglove.CompressedVideo, format "h264"):
// Annex B, NAL units after start codes, each key frame (IDR) with its SPS
// and PPS. The recorder's H.264 is "avc" (what the muxers take): NAL units
// after their lengths, the parameter sets in the caps' codec_data, and in
// the stream too when the encoder repeats them.
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
  // One access unit of length-prefixed NAL units in Annex B, the SPS and
  // PPS put before an IDR that comes without them (after the access unit
  // delimiter, which stays first); nullopt if a length runs past its end.
  std::optional<std::string> convert(std::string_view accessUnit) const;

 private:
  std::string parameterSets_;  // the SPS and PPS, each after a start code
  size_t lengthSize_ = 4;
};

}  // namespace wircam::recorder
