#include "devices/wirc/stream_sender.h"

#include <algorithm>

#include "wirc/mjpeg_packet.h"

namespace wircam::wirc {

StreamSender::StreamSender(int socket, int straySocket, SocketAddress receiver, size_t fragmentSize,
                           const Impairments& impairments)
    : socket_(socket),
      straySocket_(straySocket),
      receiver_(receiver),
      fragmentSize_(std::clamp<size_t>(fragmentSize, 1, kMaxDatagramSize - kMjpegHeaderSize)),
      impairments_(impairments),
      random_(impairments.seed),
      frameNumber_(impairments.startFrameNumber) {}

bool StreamSender::chance(double probability) {
  return probability > 0 && std::uniform_real_distribution<double>(0, 1)(random_) < probability;
}

uint32_t StreamSender::sendFrame(std::span<const uint8_t> jpeg) {
  uint32_t number = frameNumber_++;
  uint32_t reserved = impairments_.reservedBits ? 0xFFFE0000u : 0u;
  size_t offset = 0;
  bool whole = true;
  do {
    size_t fragment = fragmentSize_;
    if (impairments_.fragmentJitter > 0) {
      auto jitter = static_cast<long>(impairments_.fragmentJitter);
      fragment = static_cast<size_t>(
          std::max<long>(1, static_cast<long>(fragment) +
                                std::uniform_int_distribution<long>(-jitter, jitter)(random_)));
      fragment = std::min(fragment, kMaxDatagramSize - kMjpegHeaderSize);
    }
    size_t length = std::min(fragment, jpeg.size() - offset);
    bool last = offset + length == jpeg.size();
    MjpegPacketHeader header{kMjpegVersion | (last ? kLastPacketFlag : 0u) | reserved, number,
                             static_cast<uint32_t>(offset), static_cast<uint32_t>(length)};
    std::vector<uint8_t> datagram;
    datagram.reserve(kMjpegHeaderSize + length);
    writeMjpegHeader(header, datagram);
    datagram.insert(datagram.end(), jpeg.begin() + offset, jpeg.begin() + offset + length);
    whole = emit(std::move(datagram)) && whole;
    offset += length;
  } while (offset < jpeg.size());

  if (straySocket_ >= 0 && chance(impairments_.strayRate)) {
    // A plausible packet for this very frame, from the wrong port: a receiver
    // that does not check the source would corrupt or complete the frame.
    std::vector<uint8_t> forged;
    writeMjpegHeader({kMjpegVersion | kLastPacketFlag, number, 0, 64}, forged);
    forged.resize(forged.size() + 64, 0xEE);
    forged[kMjpegHeaderSize] = 0xFF;
    forged[kMjpegHeaderSize + 1] = 0xD8;
    if (sendDatagram(straySocket_, receiver_, forged)) ++stats_.stray;
  }
  ++stats_.frames;
  if (whole) ++stats_.framesWhole;
  return number;
}

bool StreamSender::emit(std::vector<uint8_t>&& datagram) {
  if (burstLeft_ > 0) {
    --burstLeft_;
    ++stats_.dropped;
    return false;
  }
  if (chance(impairments_.burstLoss)) {
    burstLeft_ = std::max(impairments_.burstLength, 1) - 1;
    ++stats_.dropped;
    return false;
  }
  if (chance(impairments_.loss)) {
    ++stats_.dropped;
    return false;
  }
  int copies = chance(impairments_.duplication) ? 2 : 1;
  if (copies == 2) ++stats_.duplicated;
  for (int i = 0; i < copies; ++i) {
    if (impairments_.reorderDepth <= 0) {
      put(datagram);
      continue;
    }
    heldBack_.push_back(datagram);
    if (heldBack_.size() > static_cast<size_t>(impairments_.reorderDepth)) {
      auto pick = std::uniform_int_distribution<size_t>(0, heldBack_.size() - 1)(random_);
      put(heldBack_[pick]);
      heldBack_.erase(heldBack_.begin() + static_cast<long>(pick));
    }
  }
  return true;
}

void StreamSender::put(const std::vector<uint8_t>& datagram) {
  if (sendDatagram(socket_, receiver_, datagram))
    ++stats_.datagrams;
  else
    ++stats_.sendErrors;
}

void StreamSender::flush() {
  for (const auto& datagram : heldBack_) put(datagram);
  heldBack_.clear();
}

}  // namespace wircam::wirc
