#include "recording/cut_segment.h"

#include <array>
#include <cstdint>
#include <fstream>
#include <optional>

#include "common/byte_reader.h"

namespace wircam::recorder {

namespace {

constexpr uint32_t kEbmlSegment = 0x18538067;
constexpr uint32_t kEbmlCluster = 0x1F43B675;

struct Element {
  uint64_t headerBytes = 0;
  std::optional<uint64_t> size;  // none: "unknown" (written while live)
  uint32_t id = 0;
};

// The up to 16 bytes at `offset`: enough for any element's or box's header.
std::array<uint8_t, 16> headerAt(std::ifstream& file, uint64_t offset, size_t& got) {
  std::array<uint8_t, 16> bytes{};
  file.clear();
  file.seekg(static_cast<std::streamoff>(offset));
  file.read(reinterpret_cast<char*>(bytes.data()), bytes.size());
  got = static_cast<size_t>(file.gcount());
  return bytes;
}

// An EBML variable-length integer: its length is told by the first byte's
// leading zeros; `keepMarker` for IDs, which are written with it.
std::optional<uint64_t> readVint(ByteReader& in, bool keepMarker, bool& allOnes) {
  uint8_t first = in.readU8();
  if (!in.ok() || first == 0) return std::nullopt;
  int length = 1;
  while (!(first & (0x80 >> (length - 1)))) ++length;
  uint64_t value = keepMarker ? first : (first & (0xFF >> length));
  allOnes = (first & (0xFF >> length)) == (0xFF >> length);
  for (int i = 1; i < length; ++i) {
    uint8_t next = in.readU8();
    allOnes = allOnes && next == 0xFF;
    value = value << 8 | next;
  }
  if (!in.ok()) return std::nullopt;
  return value;
}

std::optional<Element> ebmlElement(std::span<const uint8_t> bytes) {
  ByteReader in(bytes);
  bool ignored = false, unknown = false;
  auto id = readVint(in, true, ignored);
  auto size = readVint(in, false, unknown);
  if (!id || !size || *id > 0xFFFFFFFF) return std::nullopt;
  return Element{in.position(), unknown ? std::nullopt : size, static_cast<uint32_t>(*id)};
}

// Matroska: the EBML header, then the Segment, whose children (clusters,
// cues) are walked; a cluster of unknown size (the file was being written)
// is walked into, its blocks being the elements that can be cut.
bool matroskaEndsMidElement(std::ifstream& file, uint64_t fileSize) {
  uint64_t offset = 0;
  while (offset < fileSize) {
    size_t got = 0;
    auto bytes = headerAt(file, offset, got);
    auto element = ebmlElement(std::span(bytes.data(), got));
    if (!element) return true;  // a header cut off, or bytes that are none
    if (element->id == kEbmlSegment || (element->id == kEbmlCluster && !element->size)) {
      offset += element->headerBytes;  // into it
      continue;
    }
    if (!element->size) return false;  // nothing to measure it by
    if (*element->size > fileSize - offset - element->headerBytes) return true;
    offset += element->headerBytes + *element->size;
  }
  return false;
}

// MP4: top-level boxes (ftyp, moov, then moof and mdat pairs), each with its
// size; 0 runs to the end of the file.
bool mp4EndsMidBox(std::ifstream& file, uint64_t fileSize) {
  uint64_t offset = 0;
  while (offset < fileSize) {
    size_t got = 0;
    auto bytes = headerAt(file, offset, got);
    ByteReader in(std::span(bytes.data(), got));
    uint64_t size = in.readU32Be();
    in.readU32Be();  // the box's type
    if (size == 1) size = uint64_t{in.readU32Be()} << 32 | in.readU32Be();
    if (!in.ok()) return true;
    if (size == 0) return false;
    if (size < in.position() || size > fileSize - offset) return true;
    offset += size;
  }
  return false;
}

}  // namespace

bool endsMidElement(const std::filesystem::path& video) {
  std::error_code error;
  uint64_t size = std::filesystem::file_size(video, error);
  std::ifstream file(video, std::ios::binary);
  if (error || !file || size == 0) return false;
  return video.extension() == ".mp4" ? mp4EndsMidBox(file, size)
                                     : matroskaEndsMidElement(file, size);
}

}  // namespace wircam::recorder
