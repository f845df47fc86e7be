#include "foxglove/annex_b.h"

#include <algorithm>
#include <vector>

namespace wircam::recorder {

namespace {

constexpr std::string_view kStartCode("\0\0\0\1", 4);

}  // namespace

std::optional<AnnexB> AnnexB::fromAvcC(std::string_view record) {
  AnnexB converter;
  if (record.size() < 7 || record[0] != 1) return std::nullopt;  // configurationVersion 1
  converter.lengthSize_ = (static_cast<uint8_t>(record[4]) & 3) + 1;
  size_t at = 5;
  // The SPS count (5 bits), then the PPS count (a byte), each set after it.
  for (int group = 0; group < 2; ++group) {
    if (at >= record.size()) return std::nullopt;
    unsigned count = static_cast<uint8_t>(record[at++]) & (group == 0 ? 0x1f : 0xff);
    for (unsigned i = 0; i < count; ++i) {
      if (at + 2 > record.size()) return std::nullopt;
      size_t length = static_cast<size_t>(static_cast<uint8_t>(record[at])) << 8 |
                      static_cast<uint8_t>(record[at + 1]);
      at += 2;
      if (at + length > record.size()) return std::nullopt;
      converter.parameterSets_.append(kStartCode).append(record.substr(at, length));
      at += length;
    }
  }
  return converter;
}

std::optional<std::string> AnnexB::convert(std::string_view accessUnit) const {
  // The NAL units first, then the access unit in its order.
  std::vector<std::string_view> units;
  for (size_t at = 0; at < accessUnit.size();) {
    if (at + lengthSize_ > accessUnit.size()) return std::nullopt;
    size_t length = 0;
    for (size_t i = 0; i < lengthSize_; ++i)
      length = length << 8 | static_cast<uint8_t>(accessUnit[at + i]);
    at += lengthSize_;
    if (length > accessUnit.size() - at) return std::nullopt;
    units.push_back(accessUnit.substr(at, length));
    at += length;
  }
  auto typeOf = [](std::string_view unit) { return unit.empty() ? 0 : unit[0] & 0x1f; };
  constexpr int kIdr = 5, kSps = 7, kDelimiter = 9;
  bool idr = std::any_of(units.begin(), units.end(), [&](auto u) { return typeOf(u) == kIdr; });
  bool sps = std::any_of(units.begin(), units.end(), [&](auto u) { return typeOf(u) == kSps; });
  bool withSets = idr && !sps;
  std::string out;
  out.reserve(accessUnit.size() + parameterSets_.size() + 4 * units.size());
  for (size_t i = 0; i < units.size(); ++i) {
    bool delimiter = i == 0 && typeOf(units[i]) == kDelimiter;
    if (withSets && !delimiter) {
      out.append(parameterSets_);
      withSets = false;
    }
    out.append(kStartCode).append(units[i]);
  }
  return out;
}

}  // namespace wircam::recorder
