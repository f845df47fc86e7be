#include "http/rtsp_server.h"

#include <gst/app/gstappsrc.h>

#include <algorithm>

#include "common/mutex.h"
#include "http/rtsp_token_auth.h"

namespace wircam::recorder {

// One camera's mount point and the appsrc of its media while it is playing.
struct RtspServer::Mount {
  Camera camera;
  int listener = 0;
  Mutex mutex;  // the streaming thread pushes into the sources
  std::vector<GstElement*> sources WIRCAM_GUARDED_BY(mutex);
  bool removed = false;  // by a reload: no feed, no mount point
};

namespace {

// Frames are stamped by the appsrc with the media's own clock, and a new
// client may start at any frame: every JPEG is a key frame.
constexpr char kMediaLaunch[] =
    "( appsrc name=frames is-live=true format=time do-timestamp=true "
    "max-bytes=2000000 leaky-type=downstream "
    "! rtpjpegpay name=pay0 pt=26 )";

}  // namespace

Expected<std::unique_ptr<RtspServer>, std::string> RtspServer::start(const ServerAddress& address,
                                                                     std::vector<Camera> cameras,
                                                                     const std::string& token) {
  std::unique_ptr<RtspServer> self(new RtspServer());
  self->server_ = gst_rtsp_server_new();
  gst_rtsp_server_set_address(self->server_, address.listenHost().c_str());
  gst_rtsp_server_set_service(self->server_, std::to_string(address.port).c_str());
  self->token_ = token;
  for (auto& camera : cameras) self->addCamera(camera);
  if (!token.empty()) {
    GstRTSPAuth* auth = rtspTokenAuth(token);
    gst_rtsp_server_set_auth(self->server_, auth);
    g_object_unref(auth);
  }

  GError* error = nullptr;
  GSource* source = gst_rtsp_server_create_source(self->server_, nullptr, &error);
  if (!source) {
    std::string text = "--rtsp: cannot listen on port " + std::to_string(address.port) + ": " +
                       (error ? error->message : "unknown error");
    if (error) g_error_free(error);
    return unexpected(text);
  }
  self->source_ = g_source_attach(source, nullptr);
  g_source_unref(source);
  self->url_ = "rtsp://" + address.listenHost() + ":" +
               std::to_string(gst_rtsp_server_get_bound_port(self->server_));
  return self;
}

void RtspServer::addCamera(const RtspCamera& camera) {
  auto mount = std::make_unique<Mount>();
  mount->camera = camera;
  GstRTSPMediaFactory* factory = gst_rtsp_media_factory_new();
  gst_rtsp_media_factory_set_launch(factory, kMediaLaunch);
  gst_rtsp_media_factory_set_shared(factory, TRUE);
  if (!token_.empty())
    gst_rtsp_media_factory_add_role(factory, kRtspViewerRole, GST_RTSP_PERM_MEDIA_FACTORY_ACCESS,
                                    G_TYPE_BOOLEAN, TRUE, GST_RTSP_PERM_MEDIA_FACTORY_CONSTRUCT,
                                    G_TYPE_BOOLEAN, TRUE, nullptr);
  g_signal_connect(factory, "media-configure", G_CALLBACK(onMediaConfigure), mount.get());
  GstRTSPMountPoints* mounts = gst_rtsp_server_get_mount_points(server_);
  gst_rtsp_mount_points_add_factory(mounts, camera.path.c_str(), factory);
  g_object_unref(mounts);
  Mount* raw = mount.get();
  mount->listener = camera.frames->listen([raw](GstSample* sample) {
    MutexLock lock(raw->mutex);
    if (raw->sources.empty()) return;
    // Same memory, fresh metadata: the appsrc stamps it. The caps carry
    // the frame size, which rtpjpegpay needs.
    GstBuffer* jpeg =
        gst_buffer_copy_region(gst_sample_get_buffer(sample), GST_BUFFER_COPY_MEMORY, 0, -1);
    GstSample* fresh = gst_sample_new(jpeg, gst_sample_get_caps(sample), nullptr, nullptr);
    gst_buffer_unref(jpeg);
    for (GstElement* source : raw->sources) gst_app_src_push_sample(GST_APP_SRC(source), fresh);
    gst_sample_unref(fresh);
  });
  mounts_.push_back(std::move(mount));
}

void RtspServer::removeCamera(const std::string& path) {
  auto found = std::find_if(mounts_.begin(), mounts_.end(),
                            [&](const auto& m) { return !m->removed && m->camera.path == path; });
  if (found == mounts_.end()) return;
  Mount& mount = **found;
  GstRTSPMountPoints* mounts = gst_rtsp_server_get_mount_points(server_);
  gst_rtsp_mount_points_remove_factory(mounts, path.c_str());
  g_object_unref(mounts);
  mount.camera.frames->forget(mount.listener);
  // Its viewers see the stream end. The mount stays (without a feed): a
  // media still playing holds it in its callbacks until the server goes.
  {
    MutexLock lock(mount.mutex);
    for (GstElement* source : mount.sources) gst_app_src_end_of_stream(GST_APP_SRC(source));
    mount.removed = true;
  }
  // And its clients' sessions end (a client would otherwise sit on a
  // stream that never sends again).
  gst_rtsp_server_client_filter(
      server_,
      [](GstRTSPServer*, GstRTSPClient* client, gpointer mountPath) {
        gst_rtsp_client_session_filter(
            client,
            [](GstRTSPClient*, GstRTSPSession* session, gpointer pathOfMount) {
              gint matched = 0;
              bool watching = gst_rtsp_session_get_media(
                                  session, static_cast<const char*>(pathOfMount), &matched) &&
                              matched > 0;
              return watching ? GST_RTSP_FILTER_REMOVE : GST_RTSP_FILTER_KEEP;
            },
            mountPath);
        return GST_RTSP_FILTER_KEEP;
      },
      const_cast<char*>(path.c_str()));
}

RtspServer::~RtspServer() {
  for (auto& mount : mounts_) {
    if (!mount->removed) mount->camera.frames->forget(mount->listener);
    MutexLock lock(mount->mutex);
    for (GstElement* source : mount->sources) gst_object_unref(source);
    mount->sources.clear();
  }
  if (source_) g_source_remove(source_);
  if (server_) g_object_unref(server_);
}

void RtspServer::onMediaConfigure(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer data) {
  auto* mount = static_cast<Mount*>(data);
  GstElement* bin = gst_rtsp_media_get_element(media);
  GstElement* source = gst_bin_get_by_name(GST_BIN(bin), "frames");
  gst_object_unref(bin);
  if (!source) return;
  {
    MutexLock lock(mount->mutex);
    mount->sources.push_back(source);
  }
  // When the last client leaves the media is unprepared: stop feeding it.
  g_signal_connect(media, "unprepared", G_CALLBACK(+[](GstRTSPMedia* m, gpointer d) {
                     auto* unpreparedMount = static_cast<Mount*>(d);
                     GstElement* mediaBin = gst_rtsp_media_get_element(m);
                     MutexLock lock(unpreparedMount->mutex);
                     auto& list = unpreparedMount->sources;
                     for (auto it = list.begin(); it != list.end();) {
                       if (gst_object_has_as_ancestor(GST_OBJECT(*it), GST_OBJECT(mediaBin))) {
                         gst_object_unref(*it);
                         it = list.erase(it);
                       } else {
                         ++it;
                       }
                     }
                     gst_object_unref(mediaBin);
                   }),
                   mount);
}

}  // namespace wircam::recorder
