// webrtcbin's DTLS certificate, made on a thread of its own. GStreamer's
// DTLS elements make one per process, an RSA key, when the first of them
// is created: 0.2-0.4 s of a core here, 1.3 s beside three busy loops, 20 s
// once on two cores beside eight test suites. The WebRTC service starts it
// with the first viewer's offer (most recorders never have one) and holds
// the offers until it is made: the main loop never waits for it.
//
// Nothing waits for it either: a recorder stopped while the key is still
// being made ends without it (app/live_servers_module.h's endProcess).
#pragma once

namespace wircam::recorder::dtls_certificate {

// Starts making it, once a process; later calls do nothing.
void makeAhead();

// Whether it is made (offers wait until then).
bool made();

// Whether its thread is still at work, in libcrypto.
bool beingMade();

}  // namespace wircam::recorder::dtls_certificate
