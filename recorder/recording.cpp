#include "recording.h"

#include <glib-unix.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

namespace wircam::recorder {

namespace {

// GstStructure fields as JSON, recursively (lists, arrays, structures).
nlohmann::json toJson(const GValue* value) {
  GType type = G_VALUE_TYPE(value);
  if (type == G_TYPE_UINT64) return g_value_get_uint64(value);
  if (type == G_TYPE_INT64) return g_value_get_int64(value);
  if (type == G_TYPE_UINT) return g_value_get_uint(value);
  if (type == G_TYPE_INT) return g_value_get_int(value);
  if (type == G_TYPE_DOUBLE) return g_value_get_double(value);
  if (type == G_TYPE_BOOLEAN) return static_cast<bool>(g_value_get_boolean(value));
  if (type == G_TYPE_STRING) return g_value_get_string(value) ? g_value_get_string(value) : "";
  if (type == GST_TYPE_LIST || type == GST_TYPE_ARRAY) {
    nlohmann::json array = nlohmann::json::array();
    guint size =
        type == GST_TYPE_LIST ? gst_value_list_get_size(value) : gst_value_array_get_size(value);
    for (guint i = 0; i < size; ++i)
      array.push_back(toJson(type == GST_TYPE_LIST ? gst_value_list_get_value(value, i)
                                                   : gst_value_array_get_value(value, i)));
    return array;
  }
  if (type == GST_TYPE_STRUCTURE) {
    nlohmann::json object = nlohmann::json::object();
    gst_structure_foreach(
        gst_value_get_structure(value),
        [](GQuark field, const GValue* v, gpointer data) -> gboolean {
          (*static_cast<nlohmann::json*>(data))[g_quark_to_string(field)] = toJson(v);
          return TRUE;
        },
        &object);
    return object;
  }
  gchar* text = gst_value_serialize(value);
  std::string serialized = text ? text : "";
  g_free(text);
  return serialized;
}

nlohmann::json toJson(const GstStructure* structure) {
  GValue value = G_VALUE_INIT;
  g_value_init(&value, GST_TYPE_STRUCTURE);
  gst_value_set_structure(&value, structure);
  auto json = toJson(&value);
  g_value_unset(&value);
  return json;
}

std::string startTime() {
  std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%d-%H%M%S", std::localtime(&now));
  return text;
}

// A file name part made of safe characters only.
std::string fileSafe(std::string text) {
  for (char& c : text)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  return text;
}

}  // namespace

Recording::Recording(RecorderOptions options)
    : options_(std::move(options)),
      retention_(options_.outDir, {options_.maxBytes, options_.minFree},
                 [](const std::string& line) {
                   std::fprintf(stderr, "\nwirc-recorder: %s\n", line.c_str());
                 }) {}

Expected<std::unique_ptr<Recording>, std::string> Recording::create(
    const RecorderOptions& options) {
  std::error_code error;
  std::filesystem::create_directories(options.outDir, error);
  if (error) return unexpected("cannot create '" + options.outDir + "': " + error.message());
  if (access(options.outDir.c_str(), W_OK) != 0)
    return unexpected("cannot write into '" + options.outDir + "'");

  std::unique_ptr<Recording> recording(new Recording(options));
  // Crash safety: clusters of at most 1 s, so a killed recorder leaves every
  // closed segment whole and the open one playable up to its last second.
  std::string muxer =
      "muxer-factory=matroskamux "
      "muxer-properties=\"properties,max-cluster-duration=(gint64)1000000000\"";
  std::string start = startTime();
  std::string description;
  size_t index = 0;
  for (const auto& device : options.devices) {
    bool controlled = false;
    for (int camera : device.cameras) {
      auto stream = std::make_unique<Stream>();
      stream->name = fileSafe(device.label) + "-cam" + std::to_string(camera);
      auto location =
          (std::filesystem::path(options.outDir) / (stream->name + "-" + start + "-%03d.mkv"))
              .string();
      auto i = std::to_string(index++);
      stream->muxer = "mux" + i;
      std::string host = device.host.empty() ? "" : " host=" + device.host;
      std::string port = " port=" + std::to_string(device.port);
      description += "wircsrc name=src" + i + host + port + " camera=" + std::to_string(camera) +
                     " ! tee name=t" + i + " t" + i +
                     ". ! queue max-size-time=3000000000 ! splitmuxsink name=mux" + i +
                     " async-finalize=true " + muxer + " max-size-time=" +
                     std::to_string(static_cast<guint64>(options.segmentSeconds * 1e9)) +
                     " location=\"" + location + "\" ";
      if (!options.detectFamily.empty()) {
        // Detection must never hold the recording back: its queue drops.
        description +=
            "t" + i +
            ". ! queue leaky=downstream max-size-buffers=2 ! tjpegdec ! apriltagdetect name=det" +
            i + " quad-decimate=1 family=" + options.detectFamily;
        if (*device.follow && !controlled) {
          description += " ! wirccontrol name=ctl" + i + host + port;
          controlled = true;  // one controller per vehicle: the first camera's
        }
        description += " ! fakesink sync=false ";
      }
      recording->streams_.push_back(std::move(stream));
    }
  }
  GError* parseError = nullptr;
  recording->pipeline_ = gst_parse_launch(description.c_str(), &parseError);
  if (parseError) {
    std::string message = parseError->message;
    g_error_free(parseError);
    return unexpected("cannot build the pipeline (are the wircam plugins on GST_PLUGIN_PATH?): " +
                      message);
  }
  return recording;
}

Recording::~Recording() {
  if (pipeline_) {
    gst_element_set_state(pipeline_, GST_STATE_NULL);
    gst_object_unref(pipeline_);
  }
  if (loop_) g_main_loop_unref(loop_);
}

Recording::Stream* Recording::streamOf(GstMessage* message) {
  const gchar* name = GST_OBJECT_NAME(GST_MESSAGE_SRC(message));
  size_t digits = 0;
  std::string text = name ? name : "";
  while (digits < text.size() &&
         std::isdigit(static_cast<unsigned char>(text[text.size() - 1 - digits])))
    ++digits;
  if (digits == 0) return nullptr;
  size_t index = std::stoul(text.substr(text.size() - digits));
  return index < streams_.size() ? streams_[index].get() : nullptr;
}

void Recording::handleElementMessage(GstMessage* message) {
  const GstStructure* s = gst_message_get_structure(message);
  Stream* stream = streamOf(message);
  if (!s || !stream) return;
  std::string type = gst_structure_get_name(s);
  if (type == "splitmuxsink-fragment-opened") {
    stream->segment = gst_structure_get_string(s, "location");
    if (!stream->telemetry.open(stream->segment))
      std::fprintf(stderr, "wirc-recorder: cannot write %s\n", stream->telemetry.path().c_str());
    return;
  }
  if (type == "splitmuxsink-fragment-closed") {
    std::set<std::string> open;
    for (const auto& s : streams_) open.insert(s->segment);
    retention_.enforce(open);
    return;
  }

  nlohmann::json line = toJson(s);
  GstClockTime now = GST_CLOCK_TIME_NONE;
  if (GstClock* clock = gst_element_get_clock(pipeline_)) {
    now = gst_clock_get_time(clock) - gst_element_get_base_time(pipeline_);
    gst_object_unref(clock);
  }
  if (type == "wirc-session") {
    // Losses and logins of the device's session. A new login after a loss
    // starts a new segment, so the gap falls between two files.
    std::string event = gst_structure_get_string(s, "event");
    std::fprintf(stderr, "\nwirc-recorder: %s: %s\n", stream->name.c_str(), event.c_str());
    line["type"] = "session";
    line["pts"] = now;
    stream->telemetry.write(line.dump());
    // Only a login after a loss splits: the first login's event may or may
    // not arrive, depending on when wircsrc began listening.
    if (event.find("lost") != std::string::npos) stream->lost = true;
    if (event.rfind("logged in", 0) == 0 && stream->lost) {
      stream->lost = false;
      if (GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline_), stream->muxer.c_str())) {
        g_signal_emit_by_name(sink, "split-now");
        gst_object_unref(sink);
      }
    }
    return;
  }
  if (type == "wirc-stats") {
    gst_structure_get_uint64(s, "frames-complete", &stream->frames);
    gst_structure_get_uint64(s, "frames-incomplete", &stream->incomplete);
    gst_structure_get_uint64(s, "bytes", &stream->bytes);
    gst_structure_get_uint(s, "battery-mv", &stream->batteryMv);
    line["type"] = "stats";
    line["pts"] = now;
  } else if (type == "apriltag") {
    line["type"] = "detections";
    line["pts"] = line["timestamp"];
    line.erase("timestamp");
  } else if (type == "wirc-control") {
    line["type"] = "control";
    line["pts"] = line["timestamp"];
    line.erase("timestamp");
  } else {
    return;
  }
  stream->telemetry.write(line.dump());
}

gboolean Recording::onBusMessage(GstBus*, GstMessage* message, gpointer data) {
  auto* self = static_cast<Recording*>(data);
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ELEMENT:
      self->handleElementMessage(message);
      break;
    case GST_MESSAGE_WARNING: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_warning(message, &error, &debug);
      std::fprintf(stderr, "\nwirc-recorder: warning from %s: %s (%s)\n",
                   GST_OBJECT_NAME(GST_MESSAGE_SRC(message)), error->message, debug ? debug : "");
      g_error_free(error);
      g_free(debug);
      break;
    }
    case GST_MESSAGE_ERROR: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_error(message, &error, &debug);
      std::fprintf(stderr, "\nwirc-recorder: %s: %s\n%s\n",
                   GST_OBJECT_NAME(GST_MESSAGE_SRC(message)), error->message, debug ? debug : "");
      g_error_free(error);
      g_free(debug);
      self->exitCode_ = 1;
      g_main_loop_quit(self->loop_);
      break;
    }
    case GST_MESSAGE_EOS:
      g_main_loop_quit(self->loop_);
      break;
    default:
      break;
  }
  return TRUE;
}

gboolean Recording::onStop(gpointer data) {
  auto* self = static_cast<Recording*>(data);
  if (self->stopping_) {
    std::fprintf(stderr, "\nwirc-recorder: stopping now, without finishing the files\n");
    self->exitCode_ = 1;
    g_main_loop_quit(self->loop_);
    return G_SOURCE_CONTINUE;
  }
  self->stopping_ = true;
  std::fprintf(stderr,
               "\nwirc-recorder: finishing the files (send the signal again to stop at once)\n");
  // EOS from every source: each splitmuxsink closes its last segment cleanly.
  gst_element_send_event(self->pipeline_, gst_event_new_eos());
  return G_SOURCE_CONTINUE;
}

gboolean Recording::onStatus(gpointer data) {
  static_cast<Recording*>(data)->printStatus();
  return G_SOURCE_CONTINUE;
}

void Recording::printStatus() {
  bool terminal = isatty(STDOUT_FILENO);
  // On a terminal the lines are redrawn in place; in a log, appended.
  if (terminal && statusShown_) std::printf("\033[%zuA", streams_.size());
  for (auto& s : streams_) {
    double seconds = options_.statusSeconds;
    double fps = static_cast<double>(s->frames - s->lastFrames) / seconds;
    double kbps = static_cast<double>(s->bytes - s->lastBytes) * 8 / 1000 / seconds;
    double total = static_cast<double>(s->frames + s->incomplete);
    double loss = total > 0 ? 100.0 * static_cast<double>(s->incomplete) / total : 0;
    s->lastFrames = s->frames;
    s->lastBytes = s->bytes;
    std::printf("%s%-20s %7llu frames %5.1f fps  loss %4.1f%%  %7.0f kbit/s  battery %5.2f V  %s\n",
                terminal ? "\033[K" : "", s->name.c_str(),
                static_cast<unsigned long long>(s->frames), fps, loss, kbps, s->batteryMv / 1000.0,
                std::filesystem::path(s->segment).filename().c_str());
  }
  std::fflush(stdout);
  statusShown_ = true;
}

int Recording::run() {
  loop_ = g_main_loop_new(nullptr, FALSE);
  GstBus* bus = gst_element_get_bus(pipeline_);
  gst_bus_add_watch(bus, onBusMessage, this);
  g_unix_signal_add(SIGINT, onStop, this);
  g_unix_signal_add(SIGTERM, onStop, this);
  if (options_.duration) g_timeout_add(static_cast<guint>(*options_.duration * 1000), onStop, this);
  g_timeout_add(static_cast<guint>(options_.statusSeconds * 1000), onStatus, this);

  if (gst_element_set_state(pipeline_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    // The error itself comes on the bus; show it.
    GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
    if (message) {
      onBusMessage(bus, message, this);
      gst_message_unref(message);
    }
    gst_bus_remove_watch(bus);
    gst_object_unref(bus);
    return 1;
  }
  g_main_loop_run(loop_);
  gst_bus_remove_watch(bus);
  gst_object_unref(bus);
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  printStatus();
  for (auto& s : streams_) s->telemetry.close();
  return exitCode_;
}

}  // namespace wircam::recorder
