// A connection's stream as libsoup is given it: its input passes through a
// RequestHeadFramer (request_head_framer.h), so that every request head,
// over plain HTTP or TLS, is within libsoup's bound or answered 414 or 431.
// (libsoup ends each connection after one request: a server fed through
// soup_server_accept_iostream has no listener of its own, and libsoup
// keeps connections alive only for servers that have one.) When the server closes after such an answer, what
// the client still sends is read and dropped for a while first (closing
// with it unread would reset the connection, which can destroy the answer
// before the client reads it).
#pragma once

#include <gio/gio.h>

namespace wircam::recorder {

// `stream` (the connection itself, or the TLS stream over it) watched: a
// new stream whose closing closes `stream` (after the drain when one is
// due). `connection` is the socket under it, read for the drain.
GIOStream* watchRequestHeads(GIOStream* stream, GSocketConnection* connection);

}  // namespace wircam::recorder
