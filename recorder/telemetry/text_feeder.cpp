#include "telemetry/text_feeder.h"

#include <pthread.h>

#include <algorithm>

namespace wircam::recorder {

namespace {

std::mutex sharedMutex;
std::weak_ptr<TextFeeder>& sharedFeeder() {
  static auto* feeder = new std::weak_ptr<TextFeeder>;
  return *feeder;
}

void unrefAll(const std::vector<GstBuffer*>& buffers) {
  for (GstBuffer* buffer : buffers) gst_buffer_unref(buffer);
}

}  // namespace

class TextFeeder::Outlet final : public TextOutlet {
 public:
  Outlet(GstPad* input, std::shared_ptr<TextFeeder> feeder)
      : input_(GST_PAD(gst_object_ref(input))), feeder_(std::move(feeder)) {}

  ~Outlet() override {
    {
      std::unique_lock lock(feeder_->mutex_);
      std::erase(feeder_->ready_, this);
      for (const Batch& batch : batches_) unrefAll(batch.buffers);
      batches_.clear();
      // (A push blocked in the muxer returns once its pipeline stops.)
      feeder_->idle_.wait(lock, [&] { return busy_ == 0; });
    }
    gst_object_unref(input_);
  }

  void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) override {
    {
      std::lock_guard lock(feeder_->mutex_);
      if (!lines.empty() || busy_ > 0 || !batches_.empty()) {
        lines.push_back(gap);
        return feeder_->post(*this, {std::move(lines), false});
      }
      ++busy_;
    }
    push({{gap}, false});
    {
      std::lock_guard lock(feeder_->mutex_);
      --busy_;
    }
    feeder_->idle_.notify_all();
  }

  void end(std::vector<GstBuffer*> lines) override {
    std::lock_guard lock(feeder_->mutex_);
    feeder_->post(*this, {std::move(lines), true});
  }

  bool allSent() const override {
    std::lock_guard lock(feeder_->mutex_);
    return batches_.empty();
  }

  // On the text thread, or on the frame's when nothing else is under way.
  void push(const Batch& batch) {
    std::call_once(started_, [&] { start(); });
    for (GstBuffer* buffer : batch.buffers) gst_pad_chain(input_, buffer);
    if (batch.end) gst_pad_send_event(input_, gst_event_new_eos());
  }

  // Guarded by the feeder's mutex.
  std::deque<Batch> batches_;
  bool scheduled_ = false;  // in the feeder's ready_
  int busy_ = 0;            // pushes under way

 private:
  // What a source's first buffer follows: its stream, caps and segment.
  void start() {
    gst_pad_send_event(input_, gst_event_new_stream_start("wircam-telemetry"));
    GstCaps* caps = gst_caps_new_simple("text/x-raw", "format", G_TYPE_STRING, "utf8", nullptr);
    gst_pad_send_event(input_, gst_event_new_caps(caps));
    gst_caps_unref(caps);
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    gst_pad_send_event(input_, gst_event_new_segment(&segment));
  }

  GstPad* input_;
  std::shared_ptr<TextFeeder> feeder_;
  std::once_flag started_;
};

std::shared_ptr<TextFeeder> TextFeeder::shared() {
  std::lock_guard lock(sharedMutex);
  auto feeder = sharedFeeder().lock();
  if (!feeder) {
    feeder.reset(new TextFeeder);
    sharedFeeder() = feeder;
  }
  return feeder;
}

std::unique_ptr<TextOutlet> TextFeeder::outletInto(GstPad* input) {
  return std::make_unique<Outlet>(input, shared());
}

TextFeeder::TextFeeder() : thread_([this] { run(); }) {}

TextFeeder::~TextFeeder() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void TextFeeder::post(Outlet& outlet, Batch batch) {
  outlet.batches_.push_back(std::move(batch));
  if (outlet.scheduled_) return;
  outlet.scheduled_ = true;
  ready_.push_back(&outlet);
  wake_.notify_one();
}

void TextFeeder::run() {
  pthread_setname_np(pthread_self(), "wircam-text");
  // At the process's priority, unlike the links' loop and the disks'
  // writers: woken by a frame's thread, this one would take that thread's
  // processor at once, then wait in the muxer for the very frame the
  // thread was about to push, which on saturated processors waits its turn
  // behind hundreds of others (measured: cameras took 18 s to be live).
  // At an equal share the frame's thread goes on into the muxer first.
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stopping_ || !ready_.empty(); });
    if (ready_.empty()) return;
    // A batch of each track in turn: one track's stream of lines does not
    // hold back another's.
    Outlet* outlet = ready_.front();
    ready_.pop_front();
    Batch batch = std::move(outlet->batches_.front());
    outlet->batches_.pop_front();
    ++outlet->busy_;
    lock.unlock();
    outlet->push(batch);
    lock.lock();
    --outlet->busy_;
    if (outlet->batches_.empty())
      outlet->scheduled_ = false;
    else
      ready_.push_back(outlet);
    idle_.notify_all();
  }
}

}  // namespace wircam::recorder
