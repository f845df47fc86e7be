// Where a decoder can start in H.264: decided from the bitstream itself, the
// same way for every path that starts a client or a file mid-stream (the
// export, Foxglove, the replay). Neither a container's key-frame flag nor
// GStreamer's DELTA_UNIT says it: matroskademux flags no frame at all, and
// h264parse calls any I-frame a key frame, though a non-IDR I-frame (x264
// makes them at scene cuts) may be followed by frames that refer to frames
// before it.
#pragma once

#include <cstddef>
#include <string_view>

namespace wircam {

// How an access unit's NAL units are delimited: by lengths of 1, 2 or 4
// bytes before each ("avc", what the muxers take; its codec_data says the
// size), or by start codes ("byte-stream", Annex B): lengthSize 0.
struct H264Framing {
  size_t lengthSize = 4;
  static H264Framing byteStream() { return {0}; }
};

// Whether the access unit holds an IDR slice (NAL type 5): the one kind of
// frame after which nothing refers to a frame before it. A cut or damaged
// unit (a length past its end) is no place to start.
bool startsDecoding(std::string_view accessUnit, H264Framing framing = {});

}  // namespace wircam
