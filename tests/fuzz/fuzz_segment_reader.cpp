// The segment reader behind wirc-export, GET /api/export, the page's range
// download and wirc-sim --replay, on any bytes: a Matroska or fragmented
// MP4 file (MP4 when the bytes start with an ftyp box), read frame by frame
// to its end or its error. A read that does not end is a finding: the
// target runs with a per-input time limit (-timeout) under CTest.
#include <gst/gst.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "recording/cut_segment.h"
#include "recording/segment_reader.h"

using namespace wircam::recorder;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  gst_init(nullptr, nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bool mp4 = size >= 8 && std::memcmp(data + 4, "ftyp", 4) == 0;
  static const std::string stem = "/tmp/wircam-fuzz-segment-" + std::to_string(getpid());
  std::string path = stem + (mp4 ? ".mp4" : ".mkv");
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return 0;
  std::fwrite(data, 1, size, file);
  std::fclose(file);
  endsMidElement(path);
  if (auto reader = SegmentReader::open(path)) {
    while (true) {
      auto frame = (*reader)->next();
      if (!frame || !*frame) break;
    }
  }
  std::remove(path.c_str());
  return 0;
}
