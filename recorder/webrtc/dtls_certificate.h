// webrtcbin's DTLS certificate, made ahead. GStreamer's DTLS elements make
// one per process, an RSA key, when the first of them is created: 0.1-0.4 s
// of a core here, 1.3 s beside three busy loops, 20 s once on two cores
// beside eight test suites. Made at start on a thread of its own, it is
// there when the first viewer comes, and the main loop never waits for it.
//
// Nothing waits for it either: a recorder stopped while the key is still
// being made ends without it (app/live_servers_module.h's endProcess).
#pragma once

namespace wircam::recorder::dtls_certificate {

// Starts making it, once a process; later calls do nothing.
void makeAhead();

// Whether it is made (a viewer's time to come up counts from then).
bool made();

// Whether its thread is still at work, in libcrypto.
bool beingMade();

}  // namespace wircam::recorder::dtls_certificate
