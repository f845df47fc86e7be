// A plain HTTP connection's first request head, looked at (MSG_PEEK) before
// libsoup reads it. libsoup drops a connection whose head passes its 64 KiB
// bound without a word: the client sees a reset. RFC 9110 has 414 for a
// request line that long and 431 for header fields. Such a connection is
// answered so, its reason in JSON, and closed once what the client sent is
// read (at most kDrainBytes or kDrainTime; past that, a reset). Any other
// is handed to libsoup untouched, as soon as its head is whole or plainly
// ordinary.
//
// Not seen: an HTTPS head (encrypted until libsoup's TLS stream reads it)
// and the later requests of a kept-alive connection. There libsoup's reset
// stays.
#pragma once

#include <gio/gio.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <string_view>

namespace wircam::recorder {

// libsoup 3's bound on a request's line and header fields together.
inline constexpr size_t kHeadLimit = 64 * 1024;
// A head this long and not yet whole is waited for; a shorter one goes to
// libsoup as it is (a request cut into a few packets).
inline constexpr size_t kHeadWatchedFrom = 16 * 1024;
inline constexpr size_t kDrainBytes = 1 << 20;
inline constexpr std::chrono::milliseconds kDrainTime{1000};

enum class HeadVerdict { Whole, Unfinished, UriTooLong, FieldsTooLarge };

// What `peeked`, a connection's first bytes, say of its first head.
HeadVerdict judgeHead(std::string_view peeked);

// Holds `connection` (a reference of its own) until its first head is
// judged, then calls `handOn` with it, or answers it 414 or 431 and closes
// it. Main loop only.
void gateRequestHead(GSocketConnection* connection, std::function<void(GSocketConnection*)> handOn);

}  // namespace wircam::recorder
