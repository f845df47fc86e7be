// An MCAP file writer, from the format's specification (mcap.dev/spec;
// Debian has no MCAP library): chunked, with a message index per channel
// after each chunk and a summary section (schemas, channels, statistics,
// chunk indexes) and summary offsets, so that a reader can seek; every CRC
// filled in. A chunk is compressed with zstd when that saves a tenth of it
// or more, and stored as it is otherwise; one whose messages are nearly all
// on incompressible channels (JPEG, H.264) is not even tried.
//
// Messages must be written in log-time order within a chunk for the index
// to be sorted; the writer does not reorder.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {

class McapWriter {
 public:
  // Chunks of about this many uncompressed bytes, or this long: a viewer
  // seeking reads one chunk from where it lands.
  static constexpr size_t kChunkBytes = 1 << 20;
  static constexpr uint64_t kChunkNs = 2000000000;

  // Creates `path` (replacing it) and writes the magic and the header.
  static Expected<std::unique_ptr<McapWriter>, std::string> create(const std::string& path,
                                                                   const std::string& profile = "");
  // The same into `file` (written straight through: a reader of a stream
  // finds the summary at its end as ever), which it closes.
  static std::unique_ptr<McapWriter> create(FILE* file, const std::string& profile = "");
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;
  ~McapWriter();

  // Ids for the messages' records (schemas from 1; 0 is "no schema").
  uint16_t addSchema(const std::string& name, const std::string& encoding, const std::string& data);
  // `compressible`: false for channels of compressed media, which zstd
  // cannot shrink.
  uint16_t addChannel(uint16_t schema, const std::string& topic, const std::string& encoding,
                      bool compressible = true);

  // Times are nanoseconds since the Unix epoch. The message is `head`
  // followed by `body` (a frame's bytes, copied once, into the chunk).
  void write(uint16_t channel, uint64_t logTime, uint64_t publishTime, std::string_view head,
             std::string_view body = {});

  // The last chunk, the data end, the summary and the footer; false (and
  // errno) when the disk refused any of it.
  bool finish();

  uint64_t bytesWritten() const { return offset_; }

 private:
  McapWriter() = default;
  struct Schema {
    uint16_t id;
    std::string name, encoding, data;
  };
  struct Channel {
    uint16_t id, schema;
    std::string topic, encoding;
  };
  struct ChunkIndex {
    uint64_t start, end, offset, length;
    std::map<uint16_t, uint64_t> indexOffsets;
    uint64_t indexLength;
    std::string compression;
    uint64_t compressedSize, uncompressedSize;
  };

  void flushChunk();
  // A record of `opcode` to the file (and into the data section's CRC
  // while `inData_`).
  void emit(uint8_t opcode, const std::string& content);
  void put(const std::string& bytes);

  std::FILE* file_ = nullptr;
  bool failed_ = false;
  uint64_t offset_ = 0;
  uint32_t dataCrc_ = 0;
  bool inData_ = true;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  // The open chunk: its records, and per channel (time, offset in it).
  std::string chunk_;
  std::string packed_;  // chunk_ compressed
  std::set<uint16_t> incompressible_;
  uint64_t compressibleBytes_ = 0;  // of chunk_: records and compressible messages
  uint64_t chunkStart_ = UINT64_MAX, chunkEnd_ = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunkMessages_;
  std::vector<ChunkIndex> chunkIndexes_;
  std::map<uint16_t, uint32_t> sequences_;
  std::map<uint16_t, uint64_t> counts_;
  uint64_t messages_ = 0, firstTime_ = UINT64_MAX, lastTime_ = 0;
};

}  // namespace wircam::recorder
