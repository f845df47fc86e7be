#include "http/request_head_framer.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

namespace wircam::recorder {

namespace {

constexpr std::string_view kBlankLine = "\r\n\r\n";

std::string lowered(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// The value of header `name` (lower case, with its colon) in `head`, or "".
std::string headerValue(const std::string& head, const std::string& name) {
  size_t at = head.find("\n" + name);
  if (at == std::string::npos) return "";
  at += name.size() + 1;
  size_t end = head.find('\r', at);
  std::string value = head.substr(at, end == std::string::npos ? std::string::npos : end - at);
  value.erase(0, value.find_first_not_of(" \t"));
  return value;
}

std::string overlongRequest(bool requestLine) {
  return std::string("GET ") + kOverlongHeadPath + "?part=" + (requestLine ? "line" : "fields") +
         " HTTP/1.1\r\nHost: wircam\r\n\r\n";
}

}  // namespace

void RequestHeadFramer::headEnded(std::string_view head) {
  std::string lower = lowered(head);
  // A WebSocket's frames follow its upgrade, and a chunked body's chunks
  // (refused, the connection then closed) are no heads either.
  if (!headerValue(lower, "upgrade:").empty() ||
      !headerValue(lower, "transfer-encoding:").empty()) {
    state_ = State::Passing;
    return;
  }
  std::string length = headerValue(lower, "content-length:");
  bodyLeft_ = length.empty() ? 0 : std::strtoull(length.c_str(), nullptr, 10);
  state_ = bodyLeft_ > 0 ? State::Body : State::Head;
}

void RequestHeadFramer::feed(std::string_view bytes, std::string& out) {
  while (!bytes.empty()) {
    switch (state_) {
      case State::Passing:
        out.append(bytes);
        return;
      case State::Body: {
        size_t part = std::min(bodyLeft_, bytes.size());
        out.append(bytes.substr(0, part));
        bytes.remove_prefix(part);
        bodyLeft_ -= part;
        if (bodyLeft_ == 0) state_ = State::Head;
        break;
      }
      case State::Dropping: {
        // The blank line that ends the overlong head, maybe begun in the
        // bytes before these.
        std::string joined = droppedTail_ + std::string(bytes);
        size_t found = joined.find(kBlankLine);
        if (found == std::string::npos) {
          droppedTail_ = joined.substr(joined.size() - std::min<size_t>(joined.size(), 3));
          return;
        }
        bytes.remove_prefix(found + kBlankLine.size() - droppedTail_.size());
        droppedTail_.clear();
        state_ = State::Head;
        break;
      }
      case State::Head: {
        size_t from = held_.size() < 3 ? 0 : held_.size() - 3;
        size_t room = kHeadLimit + 1 - held_.size();  // one byte past the bound decides
        held_.append(bytes.substr(0, room));
        bytes.remove_prefix(std::min(room, bytes.size()));
        size_t found = held_.find(kBlankLine, from);
        if (found != std::string::npos && found + kBlankLine.size() <= kHeadLimit) {
          size_t length = found + kBlankLine.size();
          std::string head = held_.substr(0, length);
          std::string rest = held_.substr(length);
          held_.clear();
          out += head;
          headEnded(head);
          // What came after the head was taken in too: fed again.
          if (!rest.empty()) {
            std::string after = rest + std::string(bytes);
            feed(after, out);
            return;
          }
          break;
        }
        if (held_.size() <= kHeadLimit) return;  // unfinished: waited for
        size_t line = held_.find('\n');
        out += overlongRequest(line == std::string::npos || line >= kHeadLimit);
        droppedTail_ = held_.substr(held_.size() - 3);
        held_.clear();
        state_ = State::Dropping;
        break;
      }
    }
  }
}

void RequestHeadFramer::end(std::string& out) {
  if (state_ == State::Head) out += held_;
  held_.clear();
}

}  // namespace wircam::recorder
