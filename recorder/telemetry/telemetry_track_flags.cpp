#include "telemetry/telemetry_track_flags.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace wircam::recorder {

namespace {

constexpr uint32_t kSegment = 0x18538067;
constexpr uint32_t kTracks = 0x1654AE6B;
constexpr uint32_t kTrackEntry = 0xAE;
constexpr uint32_t kTrackName = 0x536E;
constexpr uint32_t kCluster = 0x1F43B675;

struct Element {
  uint32_t id;
  size_t dataStart;
  std::optional<size_t> size;  // none: "unknown" (a live segment)
};

// An EBML variable-length integer at `at`: its value and length.
std::optional<std::pair<uint64_t, size_t>> readVint(const std::vector<uint8_t>& b, size_t at,
                                                    bool keepMarker) {
  if (at >= b.size() || b[at] == 0) return std::nullopt;
  size_t length = 1;
  while (!(b[at] & (0x80 >> (length - 1)))) ++length;
  if (at + length > b.size()) return std::nullopt;
  uint64_t value = keepMarker ? b[at] : b[at] & ((0x80 >> (length - 1)) - 1);
  for (size_t i = 1; i < length; ++i) value = value << 8 | b[at + i];
  return std::pair{value, length};
}

std::optional<Element> readElement(const std::vector<uint8_t>& b, size_t at) {
  auto id = readVint(b, at, true);
  if (!id || id->second > 4) return std::nullopt;
  auto size = readVint(b, at + id->second, false);
  if (!size) return std::nullopt;
  bool unknown = size->first == (uint64_t{1} << (7 * size->second)) - 1;
  Element e{static_cast<uint32_t>(id->first), at + id->second + size->second, std::nullopt};
  if (!unknown) e.size = size->first;
  return e;
}

// The offset and size of the TrackName element holding `name` (optionally
// NUL-terminated) among the elements from `at` to `end`, descending into
// Segment → Tracks → TrackEntry and skipping everything else.
std::optional<std::pair<size_t, size_t>> findTrackName(const std::vector<uint8_t>& b, size_t at,
                                                       size_t end, std::string_view name) {
  while (at < end) {
    auto e = readElement(b, at);
    if (!e || e->id == kCluster) return std::nullopt;
    // A live Segment's size is unknown: it runs to the end of what was read.
    size_t next = e->size ? e->dataStart + *e->size : b.size();
    if (e->id == kSegment || e->id == kTracks || e->id == kTrackEntry) {
      if (auto found = findTrackName(b, e->dataStart, std::min(next, end), name)) return found;
    } else if (e->id == kTrackName && e->size && next <= b.size()) {
      std::string_view text(reinterpret_cast<const char*>(b.data() + e->dataStart), *e->size);
      if (!text.empty() && text.back() == '\0') text.remove_suffix(1);
      if (text == name) return std::pair{at, next - at};
    }
    if (!e->size) return std::nullopt;
    at = next;
  }
  return std::nullopt;
}

// Appends bytes; reserved up front (GCC 12 misreads inserts into a vector
// made from a short initialiser list as overflows).
void append(std::vector<uint8_t>& out, std::initializer_list<uint8_t> bytes) {
  out.reserve(out.size() + bytes.size() + 128);
  out.insert(out.end(), bytes);
}

// A string element: its 2-byte ID, a 1-byte size and the text.
std::vector<uint8_t> stringElement(uint8_t id0, uint8_t id1, std::string_view text) {
  std::vector<uint8_t> out;
  append(out, {id0, id1, static_cast<uint8_t>(0x80 | text.size())});
  out.insert(out.end(), text.begin(), text.end());
  return out;
}

// A Void element of `size` bytes in all (2 to 128).
void appendVoid(std::vector<uint8_t>& out, size_t size) {
  append(out, {0xEC, static_cast<uint8_t>(0x80 | (size - 2))});
  out.insert(out.end(), size - 2, 0);
}

// TrackName `name`, FlagDefault 0, FlagForced 0, then a Void to `size`.
std::optional<std::vector<uint8_t>> replacement(std::string_view name, size_t size) {
  auto out = stringElement(0x53, 0x6E, name);
  append(out, {0x88, 0x81, 0x00, 0x55, 0xAA, 0x81, 0x00});
  if (out.size() + 2 > size || size - out.size() > 128) return std::nullopt;
  appendVoid(out, size - out.size());
  return out;
}

}  // namespace

// The track's title tag, which matroskamux also writes, in a Tags element
// at the end of the file: TagString (0x4487) holding the placeholder.
static std::vector<uint8_t> titleTagPattern() {
  std::string placeholder(kTelemetryTrackPlaceholder);
  return stringElement(0x44, 0x87, std::string_view(placeholder.c_str(), placeholder.size() + 1));
}

// TagString "telemetry", then a Void to the placeholder's size.
static std::vector<uint8_t> titleTagReplacement() {
  auto bytes = stringElement(0x44, 0x87, kTelemetryTrackName);
  appendVoid(bytes, titleTagPattern().size() - bytes.size());
  return bytes;
}

// Where in `data` the title tag still holds the placeholder, if it does.
static std::optional<size_t> findTitleTag(const uint8_t* data, size_t size) {
  static const auto pattern = titleTagPattern();
  const uint8_t* end = data + size;
  const uint8_t* at =
      std::search(data, end, std::boyer_moore_horspool_searcher(pattern.begin(), pattern.end()));
  if (at == end) return std::nullopt;
  return static_cast<size_t>(at - data);
}

static bool renameTitleTag(FILE* f) {
  if (std::fseek(f, 0, SEEK_END) != 0) return false;
  long size = std::ftell(f);
  long from = std::max(0L, size - static_cast<long>(kTelemetryTrackHeaderBytes));
  std::vector<uint8_t> tail(static_cast<size_t>(size - from));
  if (std::fseek(f, from, SEEK_SET) != 0) return false;
  tail.resize(std::fread(tail.data(), 1, tail.size(), f));
  auto at = findTitleTag(tail.data(), tail.size());
  if (!at) return false;
  auto bytes = titleTagReplacement();
  return std::fseek(f, from + static_cast<long>(*at), SEEK_SET) == 0 &&
         std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
}

// MP4 boxes: [32-bit size][type], size 1 = a 64-bit size follows.
struct Box {
  std::string type;
  size_t payload, end;
};

static std::vector<Box> boxesIn(const std::vector<uint8_t>& b, size_t at, size_t end) {
  std::vector<Box> boxes;
  while (at + 8 <= end) {
    uint64_t size = uint64_t{b[at]} << 24 | b[at + 1] << 16 | b[at + 2] << 8 | b[at + 3];
    std::string type(reinterpret_cast<const char*>(b.data() + at + 4), 4);
    size_t header = 8;
    if (size == 1 && at + 16 <= end) {
      size = 0;
      for (size_t i = 8; i < 16; ++i) size = size << 8 | b[at + i];
      header = 16;
    }
    if (size < header) break;
    size_t boxEnd = size > end - at ? end : at + static_cast<size_t>(size);
    boxes.push_back({type, at + header, boxEnd});
    at = boxEnd;
  }
  return boxes;
}

static std::optional<Box> child(const std::vector<uint8_t>& b, const Box& parent,
                                const char* type) {
  for (const auto& box : boxesIn(b, parent.payload, parent.end))
    if (box.type == type) return box;
  return std::nullopt;
}

// Clears "track enabled" in the tkhd of each text track of the moov (at the
// start of a fragmented file).
static bool disableMp4TextTracks(std::vector<uint8_t>& header) {
  bool marked = false;
  for (const auto& moov : boxesIn(header, 0, header.size())) {
    if (moov.type != "moov") continue;
    for (const auto& trak : boxesIn(header, moov.payload, moov.end)) {
      if (trak.type != "trak") continue;
      auto tkhd = child(header, trak, "tkhd");
      auto mdia = child(header, trak, "mdia");
      auto hdlr = mdia ? child(header, *mdia, "hdlr") : std::nullopt;
      if (!tkhd || !hdlr || hdlr->payload + 12 > hdlr->end || tkhd->payload + 4 > tkhd->end)
        continue;
      std::string handler(reinterpret_cast<const char*>(header.data() + hdlr->payload + 8), 4);
      if (handler != "text" && handler != "sbtl" && handler != "subt") continue;
      header[tkhd->payload + 3] &= ~uint8_t{1};  // version, flags[3]
      marked = true;
    }
  }
  return marked;
}

bool markTelemetryTrackInHeader(std::vector<uint8_t>& header, TrackContainer container) {
  if (container == TrackContainer::kMp4) return disableMp4TextTracks(header);
  auto found = findTrackName(header, 0, header.size(), kTelemetryTrackPlaceholder);
  if (!found) return false;
  auto bytes = replacement(kTelemetryTrackName, found->second);
  if (!bytes) return false;
  std::copy(bytes->begin(), bytes->end(), header.begin() + static_cast<long>(found->first));
  // A streamable Matroska has its tags in the header too.
  if (auto tag = findTitleTag(header.data(), header.size())) {
    auto renamed = titleTagReplacement();
    std::copy(renamed.begin(), renamed.end(), header.begin() + static_cast<long>(*tag));
  }
  return true;
}

bool markTelemetryTrack(const std::filesystem::path& file) {
  return markTelemetryTrack(
      file, file.extension() == ".mp4" ? TrackContainer::kMp4 : TrackContainer::kMatroska);
}

bool markTelemetryTrack(const std::filesystem::path& file, TrackContainer container) {
  FILE* f = std::fopen(file.c_str(), "r+b");
  if (!f) return false;
  std::vector<uint8_t> header(kTelemetryTrackHeaderBytes);
  header.resize(std::fread(header.data(), 1, header.size(), f));
  // Written back whole: only the marked bytes differ.
  bool marked = markTelemetryTrackInHeader(header, container) && std::fseek(f, 0, SEEK_SET) == 0 &&
                std::fwrite(header.data(), 1, header.size(), f) == header.size();
  // Absent from a file cut short (the tags come last): the name stays.
  if (marked && container == TrackContainer::kMatroska) renameTitleTag(f);
  return std::fclose(f) == 0 && marked;
}

}  // namespace wircam::recorder
