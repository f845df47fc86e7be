#include "export/mcap_writer.h"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace wircam::recorder {

namespace {

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr size_t kMagicSize = 8;

// The format's little-endian fields.
struct Bytes {
  std::string out;
  Bytes& u8(uint8_t v) { return raw(&v, 1); }
  Bytes& u16(uint16_t v) { return le(v, 2); }
  Bytes& u32(uint32_t v) { return le(v, 4); }
  Bytes& u64(uint64_t v) { return le(v, 8); }
  Bytes& str(const std::string& s) {  // uint32 length, then the bytes
    u32(static_cast<uint32_t>(s.size()));
    out += s;
    return *this;
  }
  Bytes& raw(const void* data, size_t size) {
    out.append(static_cast<const char*>(data), size);
    return *this;
  }
  Bytes& le(uint64_t v, int size) {
    for (int i = 0; i < size; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    return *this;
  }
};

std::string record(uint8_t opcode, const std::string& content) {
  return Bytes().u8(opcode).u64(content.size()).raw(content.data(), content.size()).out;
}

uint32_t crcOf(const std::string& bytes, uint32_t crc = 0) {
  return static_cast<uint32_t>(
      crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

}  // namespace

Expected<std::unique_ptr<McapWriter>, std::string> McapWriter::create(const std::string& path,
                                                                      const std::string& profile) {
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return unexpected("cannot create " + path + ": " + std::strerror(errno));
  return create(file, profile);
}

std::unique_ptr<McapWriter> McapWriter::create(FILE* file, const std::string& profile) {
  std::unique_ptr<McapWriter> writer(new McapWriter);
  writer->file_ = file;
  writer->put(std::string(kMagic, kMagicSize));
  writer->emit(kHeader, Bytes().str(profile).str("wircam wirc-export").out);
  return writer;
}

McapWriter::~McapWriter() {
  if (file_) std::fclose(file_);
}

uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding,
                               const std::string& data) {
  auto id = static_cast<uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, name, encoding, data});
  // Inside the chunk, ahead of the messages that use it: a reader reading
  // straight through meets it first.
  std::string schema = record(kSchema, Bytes().u16(id).str(name).str(encoding).str(data).out);
  compressibleBytes_ += schema.size();
  chunk_ += schema;
  return id;
}

uint16_t McapWriter::addChannel(uint16_t schema, const std::string& topic,
                                const std::string& encoding, bool compressible) {
  auto id = static_cast<uint16_t>(channels_.size());
  channels_.push_back({id, schema, topic, encoding});
  if (!compressible) incompressible_.insert(id);
  std::string channel =
      record(kChannel, Bytes().u16(id).u16(schema).str(topic).str(encoding).u32(0).out);
  compressibleBytes_ += channel.size();
  chunk_ += channel;
  return id;
}

void McapWriter::write(uint16_t channel, uint64_t logTime, uint64_t publishTime,
                       std::string_view head, std::string_view body) {
  chunkMessages_[channel].emplace_back(logTime, chunk_.size());
  size_t before = chunk_.size();
  // Straight into the chunk: a frame's bytes are copied once.
  constexpr size_t kFields = 2 + 4 + 8 + 8;
  chunk_ += Bytes()
                .u8(kMessage)
                .u64(kFields + head.size() + body.size())
                .u16(channel)
                .u32(sequences_[channel]++)
                .u64(logTime)
                .u64(publishTime)
                .out;
  chunk_ += head;
  chunk_ += body;
  if (!incompressible_.count(channel)) compressibleBytes_ += chunk_.size() - before;
  chunkStart_ = std::min(chunkStart_, logTime);
  chunkEnd_ = std::max(chunkEnd_, logTime);
  firstTime_ = std::min(firstTime_, logTime);
  lastTime_ = std::max(lastTime_, logTime);
  ++counts_[channel];
  ++messages_;
  if (chunk_.size() >= kChunkBytes || chunkEnd_ - chunkStart_ >= kChunkNs) flushChunk();
}

void McapWriter::flushChunk() {
  if (chunkMessages_.empty() && chunk_.empty()) return;
  if (chunkMessages_.empty()) chunkStart_ = chunkEnd_ = 0;  // schemas and channels only
  std::string compression;
  // Compressed frames do not shrink: when the rest of the chunk is under a
  // tenth of it, zstd could not save a tenth, and is not tried.
  bool worthTrying = compressibleBytes_ >= chunk_.size() / 10;
  compressibleBytes_ = 0;
  size_t size = 0;
  if (worthTrying) {
    // The buffer is kept from chunk to chunk: no fresh pages to fault in.
    packed_.resize(ZSTD_compressBound(chunk_.size()));
    // Level 1: the fastest; telemetry's JSON text compresses at any level.
    size = ZSTD_compress(packed_.data(), packed_.size(), chunk_.data(), chunk_.size(), 1);
  }
  bool pays = worthTrying && !ZSTD_isError(size) && size < chunk_.size() - chunk_.size() / 10;
  if (pays) {
    packed_.resize(size);
    compression = "zstd";
  }
  const std::string& stored = pays ? packed_ : chunk_;
  ChunkIndex index{};
  index.start = chunkStart_;
  index.end = chunkEnd_;
  index.offset = offset_;
  index.compression = compression;
  index.compressedSize = stored.size();
  index.uncompressedSize = chunk_.size();
  // The record's head, then the stored bytes as they are (not copied into it).
  Bytes fields;
  fields.u64(chunkStart_)
      .u64(chunkEnd_)
      .u64(chunk_.size())
      .u32(crcOf(chunk_))
      .str(compression)
      .u64(stored.size());
  put(Bytes().u8(kChunk).u64(fields.out.size() + stored.size()).out + fields.out);
  put(stored);
  index.length = offset_ - index.offset;
  uint64_t indexesStart = offset_;
  for (auto& [channel, entries] : chunkMessages_) {
    // In log-time order (lines come a little out of it).
    std::stable_sort(entries.begin(), entries.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    Bytes list;
    for (const auto& [time, at] : entries) list.u64(time).u64(at);
    index.indexOffsets[channel] = offset_;
    emit(kMessageIndex, Bytes().u16(channel).str(list.out).out);
  }
  index.indexLength = offset_ - indexesStart;
  chunkIndexes_.push_back(std::move(index));
  chunk_.clear();
  chunkMessages_.clear();
  chunkStart_ = UINT64_MAX;
  chunkEnd_ = 0;
}

bool McapWriter::finish() {
  flushChunk();
  emit(kDataEnd, Bytes().u32(dataCrc_).out);
  inData_ = false;
  // The summary: every schema and channel again, the statistics, the chunk
  // indexes; each kind a group the summary offsets point at.
  uint64_t summaryStart = offset_;
  std::string summary;
  std::vector<std::string> offsets;
  auto group = [&](uint8_t opcode, const std::vector<std::string>& records) {
    if (records.empty()) return;
    uint64_t start = summaryStart + summary.size();
    for (const auto& r : records) summary += r;
    offsets.push_back(
        record(kSummaryOffset,
               Bytes().u8(opcode).u64(start).u64(summaryStart + summary.size() - start).out));
  };
  std::vector<std::string> records;
  for (const auto& s : schemas_)
    records.push_back(
        record(kSchema, Bytes().u16(s.id).str(s.name).str(s.encoding).str(s.data).out));
  group(kSchema, records);
  records.clear();
  for (const auto& c : channels_)
    records.push_back(
        record(kChannel, Bytes().u16(c.id).u16(c.schema).str(c.topic).str(c.encoding).u32(0).out));
  group(kChannel, records);
  Bytes counts;
  for (const auto& [channel, count] : counts_) counts.u16(channel).u64(count);
  group(kStatistics, {record(kStatistics, Bytes()
                                              .u64(messages_)
                                              .u16(static_cast<uint16_t>(schemas_.size()))
                                              .u32(static_cast<uint32_t>(channels_.size()))
                                              .u32(0)
                                              .u32(0)
                                              .u32(static_cast<uint32_t>(chunkIndexes_.size()))
                                              .u64(messages_ ? firstTime_ : 0)
                                              .u64(lastTime_)
                                              .str(counts.out)
                                              .out)});
  records.clear();
  for (const auto& c : chunkIndexes_) {
    Bytes offsetsOf;
    for (const auto& [channel, at] : c.indexOffsets) offsetsOf.u16(channel).u64(at);
    records.push_back(record(kChunkIndex, Bytes()
                                              .u64(c.start)
                                              .u64(c.end)
                                              .u64(c.offset)
                                              .u64(c.length)
                                              .str(offsetsOf.out)
                                              .u64(c.indexLength)
                                              .str(c.compression)
                                              .u64(c.compressedSize)
                                              .u64(c.uncompressedSize)
                                              .out));
  }
  group(kChunkIndex, records);
  uint64_t summaryOffsetStart = summaryStart + summary.size();
  std::string tail = summary;
  for (const auto& o : offsets) tail += o;
  // The footer's CRC covers the summary up to its own CRC field.
  std::string footerHead =
      Bytes().u8(kFooter).u64(20).u64(summaryStart).u64(summaryOffsetStart).out;
  uint32_t summaryCrc = crcOf(footerHead, crcOf(tail));
  put(tail + footerHead + Bytes().u32(summaryCrc).out + std::string(kMagic, kMagicSize));
  bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  return closed && !failed_;
}

void McapWriter::emit(uint8_t opcode, const std::string& content) { put(record(opcode, content)); }

void McapWriter::put(const std::string& bytes) {
  if (inData_) dataCrc_ = crcOf(bytes, dataCrc_);
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) failed_ = true;
  offset_ += bytes.size();
}

}  // namespace wircam::recorder
