// HttpServer's WHEP endpoint (RFC 9725, without trickle ICE): a viewer
// POSTs its offer as application/sdp and gets the answer, with every
// candidate the recorder gathered, and its session's Location, which it
// DELETEs when it leaves. The drive data channel's messages are obeyed
// here as the WebSocket's are.
#include <memory>

#include "fleet/drive_command.h"
#include "http/camera_feed.h"
#include "http/http_responses.h"
#include "http/http_server.h"

namespace wircam::recorder {

namespace {

// The viewer's IP address as libsoup saw it.
std::string peerAddress(SoupServerMessage* message) {
  const char* host = soup_server_message_get_remote_host(message);
  return host ? host : "";
}

}  // namespace

void HttpServer::serveWhep(SoupServerMessage* message, const Route& route) {
  if (!webrtc_)
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                            webrtcOff_ + "; the live view is /live/CAMERA.mjpg");
  if (route.kind == Route::Kind::WhepSession) {
    if (!webrtc_->end(route.name, route.action))
      return respondJsonError(message, SOUP_STATUS_NOT_FOUND, "no such WHEP session");
    return respond(message, SOUP_STATUS_OK, "application/json", "{}");
  }
  const char* type = soup_message_headers_get_content_type(
      soup_server_message_get_request_headers(message), nullptr);
  if (g_strcmp0(type, "application/sdp") != 0)
    return respondJsonError(message, SOUP_STATUS_UNSUPPORTED_MEDIA_TYPE,
                            "the offer goes as Content-Type: application/sdp");
  SoupMessageBody* body = soup_server_message_get_request_body(message);
  std::string_view offer(body->data ? body->data : "", static_cast<size_t>(body->length));

  // The answer may come after the viewer has gone: then it is not written,
  // and the session is ended at once.
  auto gone = std::make_shared<bool>(false);
  gulong finished = g_signal_connect_data(
      message, "finished", G_CALLBACK(+[](SoupServerMessage*, gpointer flag) {
        **static_cast<std::shared_ptr<bool>*>(flag) = true;
      }),
      new std::shared_ptr<bool>(gone),
      [](gpointer flag, GClosure*) { delete static_cast<std::shared_ptr<bool>*>(flag); },
      GConnectFlags(0));
  // Answered later; a status now keeps libsoup from taking the request for
  // a WebSocket handshake (which any unanswered one is taken to be).
  soup_server_message_set_status(message, SOUP_STATUS_ACCEPTED, nullptr);
  soup_server_message_pause(message);
  std::string camera = route.name;
  webrtc_->offer(camera, offer, peerAddress(message),
                 [this, message, gone, finished,
                  camera](Expected<WebRtcService::Answer, WebRtcService::Refusal> answer) {
                   if (*gone) {
                     if (answer) webrtc_->end(camera, answer->session);
                     return;
                   }
                   g_signal_handler_disconnect(message, finished);
                   if (!answer) {
                     respondJsonError(message, answer.error().status, answer.error().why);
                   } else {
                     std::string location = "/api/cameras/" + camera + "/whep/" + answer->session;
                     soup_message_headers_replace(soup_server_message_get_response_headers(message),
                                                  "Location", location.c_str());
                     respond(message, SOUP_STATUS_CREATED, "application/sdp", answer->sdp);
                   }
                   soup_server_message_unpause(message);
                 });
}

std::string HttpServer::driveOverDataChannel(const std::string& camera,
                                             std::optional<std::string_view> text) {
  if (content_.token.empty())
    return nlohmann::json{{"error", "driving needs the server started with --http-token"}}.dump();
  return obeyDriveMessage(text, [this, &camera](double steering, double throttle) {
    return content_.drive(camera, steering, throttle);
  });
}

}  // namespace wircam::recorder
