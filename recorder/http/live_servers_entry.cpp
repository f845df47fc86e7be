// The one function wirc-recorder-servers.so exports: its table of servers
// (live_servers.h), which the recorder looks up when it loads the module.
#include <gmodule.h>

#include "http/foxglove_server.h"
#include "http/http_server.h"
#include "http/rtsp_server.h"
#include "webrtc/dtls_certificate.h"

namespace wircam::recorder {
namespace {

Expected<std::unique_ptr<WebServer>, std::string> startWeb(const ServerAddress& address,
                                                           WebContent content,
                                                           std::chrono::milliseconds idleTimeout) {
  auto server = HttpServer::start(address, std::move(content), idleTimeout);
  if (!server) return unexpected(server.error());
  return std::unique_ptr<WebServer>(std::move(*server));
}

Expected<std::unique_ptr<RtspService>, std::string> startRtsp(const ServerAddress& address,
                                                              std::vector<RtspCamera> cameras,
                                                              const std::string& token) {
  auto server = RtspServer::start(address, std::move(cameras), token);
  if (!server) return unexpected(server.error());
  return std::unique_ptr<RtspService>(std::move(*server));
}

Expected<std::unique_ptr<FoxgloveService>, std::string> startFoxglove(
    const ServerAddress& address, FoxgloveContent content, std::chrono::milliseconds idleTimeout) {
  auto server = FoxgloveServer::start(address, std::move(content), idleTimeout);
  if (!server) return unexpected(server.error());
  return std::unique_ptr<FoxgloveService>(std::move(*server));
}

}  // namespace
}  // namespace wircam::recorder

extern "C" G_MODULE_EXPORT const wircam::recorder::LiveServers* wircam_live_servers() {
  static const wircam::recorder::LiveServers servers{
      &wircam::recorder::startWeb, &wircam::recorder::startRtsp, &wircam::recorder::startFoxglove,
      &wircam::recorder::dtls_certificate::beingMade};
  return &servers;
}
