#include "http/rtsp_server.h"

#include <algorithm>

#include "http/rtsp_media_feed.h"
#include "http/rtsp_token_auth.h"

namespace wircam::recorder {

// One camera's mount point, and its frames' way into the media clients play.
struct RtspServer::Mount {
  Camera camera;
  int listener = 0;
  RtspMediaFeed feed;
  bool removed = false;  // by a reload: no feed, no mount point
};

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
  std::string launch = std::string("( ") + kRtspFrameSource + " ! rtpjpegpay name=pay0 pt=26 )";
  gst_rtsp_media_factory_set_launch(factory, launch.c_str());
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
  mount->listener = camera.frames->listen([raw](GstSample* sample) { raw->feed.push(sample); });
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
  mount.feed.end();
  mount.removed = true;
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
  mount->feed.add(source);
  gst_object_unref(source);
  // When the last client leaves the media is unprepared: stop feeding it.
  g_signal_connect(media, "unprepared", G_CALLBACK(+[](GstRTSPMedia* m, gpointer d) {
                     GstElement* mediaBin = gst_rtsp_media_get_element(m);
                     static_cast<Mount*>(d)->feed.removeWithin(mediaBin);
                     gst_object_unref(mediaBin);
                   }),
                   mount);
}

}  // namespace wircam::recorder
