#include "webrtc/webrtc_service.h"

#include <gio/gio.h>
#include <malloc.h>

#include <utility>

#include "log_line.h"
#include "webrtc/dtls_certificate.h"
#include "webrtc/whep_sdp.h"

namespace wircam::recorder {

namespace {

// The addresses of a TURN server ("turn://user:password@host:port"): a
// viewer's relay candidates point there.
std::set<std::string> turnAddresses(const std::string& url) {
  std::set<std::string> addresses;
  gchar* host = nullptr;
  if (url.empty() ||
      !g_uri_split(url.c_str(), G_URI_FLAGS_HAS_PASSWORD, nullptr, nullptr, &host, nullptr, nullptr,
                   nullptr, nullptr, nullptr) ||
      !host)
    return addresses;
  GList* resolved = g_resolver_lookup_by_name(g_resolver_get_default(), host, nullptr, nullptr);
  for (GList* at = resolved; at; at = at->next) {
    gchar* text = g_inet_address_to_string(G_INET_ADDRESS(at->data));
    addresses.insert(text);
    g_free(text);
  }
  g_resolver_free_addresses(resolved);
  g_free(host);
  return addresses;
}

}  // namespace

std::vector<std::string> WebRtcService::missingElements() {
  std::vector<std::string> missing;
  for (const char* name : {"webrtcbin", "dtlsdec", "nicesrc", "nicesink", "vp8enc", "rtpvp8pay",
                           "rtph264pay", "tjpegdec"}) {
    if (GstElementFactory* factory = gst_element_factory_find(name))
      gst_object_unref(factory);
    else
      missing.push_back(name);
  }
  return missing;
}

WebRtcService::WebRtcService(std::vector<Camera> cameras, Settings settings)
    : cameras_(std::move(cameras)),
      settings_(std::move(settings)),
      allowedHosts_(turnAddresses(settings_.servers.turn)) {
  sweepTimer_ = g_timeout_add(
      500,
      [](gpointer self) -> gboolean {
        static_cast<WebRtcService*>(self)->sweep(std::chrono::steady_clock::now());
        return G_SOURCE_CONTINUE;
      },
      this);
}

WebRtcService::~WebRtcService() {
  alive_.reset();
  g_source_remove(sweepTimer_);
  // The offers still waiting go with their requests, which the server ends.
  if (certificateCheck_) g_source_remove(certificateCheck_);
  viewers_.clear();  // before their encoders
  encoders_.clear();
}

void WebRtcService::addCamera(Camera camera) { cameras_.push_back(std::move(camera)); }

void WebRtcService::removeCamera(const std::string& name) {
  std::vector<std::string> sessions;
  for (const auto& [session, viewer] : viewers_)
    if (viewer.camera == name) sessions.push_back(session);
  for (const auto& session : sessions) remove(session);
  std::erase_if(cameras_, [&](const Camera& c) { return c.name == name; });
}

const WebRtcService::Camera* WebRtcService::cameraNamed(const std::string& name) const {
  for (const auto& camera : cameras_)
    if (camera.name == name) return &camera;
  return nullptr;
}

void WebRtcService::offer(const std::string& camera, std::string_view sdp,
                          const std::string& viewerAddress, Done done) {
  // The DTLS certificate is made for the first offer, on a thread of its
  // own (a quarter of a second of a core, seconds on a loaded or small
  // machine, and most recorders never have a viewer): the offers wait for
  // it, the main loop does not (webrtcbin would make it on it).
  if (!dtls_certificate::made()) {
    dtls_certificate::makeAhead();
    waitingForCertificate_.push_back({camera, std::string(sdp), viewerAddress, std::move(done)});
    if (!certificateCheck_) certificateCheck_ = g_timeout_add(10, offerWhenCertified, this);
    return;
  }
  const Camera* source = cameraNamed(camera);
  if (!source) return done(unexpected(Refusal{404, "no camera named '" + camera + "'"}));
  if (viewers_.size() >= kMaxViewers)
    return done(unexpected(Refusal{503, "already " + std::to_string(kMaxViewers) +
                                            " WebRTC viewers; try again later, or "
                                            "/live/CAMERA.mjpg"}));
  auto allowed = allowedHosts_;
  allowed.insert(viewerAddress);
  auto offer = readViewerOffer(sdp, allowed);
  if (!offer) return done(unexpected(Refusal{400, offer.error()}));
  // The recording's own H.264 when the viewer takes it: nothing is encoded
  // again. Otherwise VP8, encoded here.
  bool passThrough = source->h264 && offer->h264Payload >= 0;
  if (!passThrough && offer->vp8Payload < 0)
    return done(unexpected(Refusal{400,
                                   "this camera goes out as VP8 (its recording is not "
                                   "H.264); the offer's video does not take VP8"}));
  std::string key = camera + (passThrough ? " h264" : " vp8");
  auto& encoder = encoders_[key];
  if (!encoder) {
    auto started =
        CameraEncoder::start(passThrough ? *source->h264 : *source->frames, camera,
                             passThrough ? WebRtcVideo::kH264 : WebRtcVideo::kVp8, settings_.kbps);
    if (!started) {
      encoders_.erase(key);
      return done(unexpected(Refusal{500, started.error()}));
    }
    encoder = std::move(*started);
  }
  gchar* uuid = g_uuid_string_random();
  std::string session = uuid;
  g_free(uuid);
  if (offer->droppedCandidates)
    logLine("webrtc: " + camera + ": left out " + std::to_string(offer->droppedCandidates) +
            " ICE candidate(s) of the offer for other hosts than the viewer " + viewerAddress);
  WebRtcViewer::Events events;
  events.answered = [this, session](Expected<std::string, std::string> answer) {
    auto viewer = viewers_.find(session);
    if (viewer == viewers_.end() || !viewer->second.unanswered) return;
    Done reply = std::exchange(viewer->second.unanswered, nullptr);
    if (!answer) {
      removeLater(session);
      return reply(unexpected(Refusal{400, answer.error()}));
    }
    // The browser has the idle timeout to connect from its answer on.
    viewer->second.downSince = std::chrono::steady_clock::now();
    if (viewer->second.peer->candidatesGathered() == 0)
      logLine("webrtc: " + viewer->second.camera + ": answered session " + session +
              " without an ICE candidate of the recorder's (none gathered in time): only a "
              "viewer the recorder can reach will connect");
    reply(Answer{*answer, session});
  };
  events.ended = [this, session] { removeLater(session); };
  events.driveMessage = [this, camera](std::optional<std::string_view> text) {
    return settings_.driveMessage(camera, text);
  };
  events.driveClosed = [this, camera] { settings_.neutral(camera); };
  Viewer& viewer = viewers_[session];
  viewer.camera = camera;
  viewer.encoder = key;
  viewer.downSince = std::chrono::steady_clock::now();
  viewer.unanswered = std::move(done);
  viewer.peer = std::make_unique<WebRtcViewer>(*encoder, *offer, settings_.servers, events);
  logLine("webrtc: " + camera + ": viewer " + viewerAddress + " (session " + session + ", " +
          (passThrough ? "the recording's H.264" : "VP8") + "), " +
          std::to_string(viewers_.size()) + " now");
}

gboolean WebRtcService::offerWhenCertified(gpointer self) {
  auto* service = static_cast<WebRtcService*>(self);
  if (!dtls_certificate::made()) return G_SOURCE_CONTINUE;
  service->certificateCheck_ = 0;
  auto waiting = std::exchange(service->waitingForCertificate_, {});
  for (auto& offer : waiting)
    service->offer(offer.camera, offer.sdp, offer.viewerAddress, std::move(offer.done));
  return G_SOURCE_REMOVE;
}

bool WebRtcService::end(const std::string& camera, const std::string& session) {
  auto viewer = viewers_.find(session);
  if (viewer == viewers_.end() || viewer->second.camera != camera) return false;
  remove(session);
  return true;
}

void WebRtcService::sweep(std::chrono::steady_clock::time_point now) {
  std::vector<std::string> expired;
  for (auto& [session, viewer] : viewers_) {
    // Up: released when its browser has been silent that long (a closed
    // tab, a lost network); not up yet: when it has not come up in time.
    if (viewer.peer->state() == GST_WEBRTC_PEER_CONNECTION_STATE_CONNECTED) {
      viewer.downSince.reset();
      if (now - viewer.peer->lastHeard() > settings_.idleTimeout) expired.push_back(session);
      continue;
    }
    if (!viewer.downSince) viewer.downSince = now;
    if (now - *viewer.downSince > settings_.idleTimeout) expired.push_back(session);
  }
  for (const auto& session : expired) remove(session);
}

void WebRtcService::removeLater(const std::string& session) {
  // Not from inside the viewer's own callback: on the main loop's next turn.
  struct Removal {
    std::weak_ptr<WebRtcService*> service;
    std::string session;
  };
  g_idle_add_full(
      G_PRIORITY_DEFAULT,
      [](gpointer data) -> gboolean {
        auto* removal = static_cast<Removal*>(data);
        if (auto service = removal->service.lock()) (*service)->remove(removal->session);
        return G_SOURCE_REMOVE;
      },
      new Removal{alive_, session}, [](gpointer data) { delete static_cast<Removal*>(data); });
}

void WebRtcService::remove(const std::string& session) {
  auto viewer = viewers_.find(session);
  if (viewer == viewers_.end()) return;
  std::string camera = viewer->second.camera, key = viewer->second.encoder;
  Done unanswered = std::move(viewer->second.unanswered);
  if (unanswered)
    logLine("webrtc: " + camera + ": session " + session +
            " not answered within the idle timeout: " + viewer->second.peer->preparation());
  viewers_.erase(viewer);
  logLine("webrtc: " + camera + ": viewer gone (session " + session + "), " +
          std::to_string(viewers_.size()) + " now");
  // The encoder runs only while someone watches.
  bool watched = false;
  for (const auto& [id, other] : viewers_) watched = watched || other.encoder == key;
  if (!watched) encoders_.erase(key);
  // Each viewer's threads leave memory in glibc's per-thread arenas, kept
  // for reuse; when nobody watches, it goes back to the system.
  if (viewers_.empty()) malloc_trim(0);
  // Gone before it could answer (its candidates not gathered within the
  // idle timeout, a loaded machine): the request is answered all the same.
  if (unanswered)
    unanswered(unexpected(Refusal{503,
                                  "the viewer's connection could not be prepared in time; "
                                  "try again, or /live/CAMERA.mjpg"}));
}

}  // namespace wircam::recorder
