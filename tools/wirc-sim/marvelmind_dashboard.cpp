#include "marvelmind_dashboard.h"

#include <sys/epoll.h>

#include <cmath>
#include <map>
#include <mutex>
#include <random>

#include "link/event_loop.h"

namespace wircam::sim {

using link::Clock;
using link::EventLoop;
namespace mm = marvelmind;

class MarvelmindDashboard::Impl {
 public:
  Impl(DashboardConfig config, TruthSource truth, UniqueFd socket);
  ~Impl();

  void measure();
  void onReadable();

  const DashboardConfig config_;
  const TruthSource truth_;
  UniqueFd socket_;
  const Clock::time_point started_ = Clock::now();
  const Clock::duration period_;
  EventLoop& loop_ = EventLoop::shared();
  EventLoop::Id watch_ = 0, measureTimer_ = 0;
  Clock::time_point nextMeasurement_ = started_;

  mutable std::mutex mutex_;  // guards what follows
  std::mt19937 random_;
  std::map<uint8_t, mm::Reply> latest_;  // per beacon, in mm
  DashboardStats stats_;
};

MarvelmindDashboard::Impl::Impl(DashboardConfig config, TruthSource truth, UniqueFd socket)
    : config_(std::move(config)),
      truth_(std::move(truth)),
      socket_(std::move(socket)),
      period_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / config_.rate))),
      random_(config_.seed) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  measureTimer_ = loop_.addTimer([this] { measure(); });
  loop_.arm(measureTimer_, started_);
}

MarvelmindDashboard::Impl::~Impl() {
  loop_.invoke([this] {
    loop_.remove(watch_);
    loop_.remove(measureTimer_);
  });
}

void MarvelmindDashboard::Impl::measure() {
  auto now = Clock::now();
  // Stamped at the measurement's scheduled instant: a late wake of this
  // process is not a late measurement.
  double seconds = std::chrono::duration<double>(nextMeasurement_ - started_).count();
  std::vector<std::vector<uint8_t>> pushes;
  {
    std::lock_guard lock(mutex_);
    std::normal_distribution<double> noise(0, config_.noise);
    std::bernoulli_distribution missed(config_.dropout);
    for (size_t i = 0; i < config_.beacons.size(); ++i) {
      if (missed(random_)) {
        ++stats_.missed;
        continue;
      }
      auto truth = truth_(i);
      auto millimetres = [&](double metres) {
        return static_cast<int32_t>(std::lround((metres + noise(random_)) * 1000));
      };
      mm::Reply reply{.beacon = config_.beacons[i],
                      .resolution = config_.pushResolution,
                      .timestamp = mm::timestampOf(seconds, config_.timestampUnit),
                      .xMm = millimetres(truth[0]),
                      .yMm = millimetres(truth[1]),
                      .zMm = millimetres(truth[2])};
      latest_[reply.beacon] = reply;
      ++stats_.measurements;
      if (config_.pushTo) pushes.push_back(mm::encode(reply));
    }
  }
  for (const auto& push : pushes)
    if (sendDatagram(socket_.get(), *config_.pushTo, push)) {
      std::lock_guard lock(mutex_);
      ++stats_.pushed;
    }
  // Whole periods from the start: the rate holds however late a wake is.
  do nextMeasurement_ += period_;
  while (nextMeasurement_ <= now);
  loop_.arm(measureTimer_, nextMeasurement_);
}

void MarvelmindDashboard::Impl::onReadable() {
  std::array<uint8_t, 256> buffer;
  std::vector<std::pair<SocketAddress, std::vector<uint8_t>>> answers;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    std::lock_guard lock(mutex_);
    ++stats_.requests;
    auto request = mm::decodeRequest(datagram);
    auto found = request ? latest_.find(request->beacon) : latest_.end();
    // Malformed, or a beacon it has no position of: no answer.
    if (found == latest_.end()) return void(++stats_.badRequests);
    mm::Reply reply = found->second;
    reply.resolution = request->resolution;
    answers.emplace_back(from, mm::encode(reply));
  });
  for (const auto& [to, answer] : answers)
    if (sendDatagram(socket_.get(), to, answer)) {
      std::lock_guard lock(mutex_);
      ++stats_.replies;
    }
}

Expected<std::unique_ptr<MarvelmindDashboard>, std::string> MarvelmindDashboard::start(
    DashboardConfig config, TruthSource truth) {
  if (config.beacons.empty()) return unexpected(std::string("the dashboard needs a beacon"));
  if (!(config.rate > 0 && config.rate <= 100))
    return unexpected(std::string("--marvelmind-rate is 0..100 Hz"));
  auto address = SocketAddress::resolve(config.bindAddress, config.port);
  if (!address) return unexpected(address.error());
  auto socket = bindUdp(*address);
  if (!socket) return unexpected("Marvelmind dashboard: " + socket.error());
  setNonBlocking(socket->get());
  std::unique_ptr<MarvelmindDashboard> dashboard(new MarvelmindDashboard());
  dashboard->impl_ =
      std::make_unique<Impl>(std::move(config), std::move(truth), std::move(*socket));
  return dashboard;
}

MarvelmindDashboard::~MarvelmindDashboard() = default;

uint16_t MarvelmindDashboard::port() const { return localAddress(impl_->socket_.get()).port(); }

DashboardStats MarvelmindDashboard::stats() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->stats_;
}

std::string MarvelmindDashboard::summary() const {
  auto s = stats();
  auto n = [](uint64_t value) { return std::to_string(value); };
  return "Marvelmind dashboard: " + n(s.measurements) + " measurements (" + n(s.missed) +
         " missed), " + n(s.requests) + " requests (" + n(s.badRequests) + " refused), " +
         n(s.replies) + " replies, " + n(s.pushed) + " pushed";
}

}  // namespace wircam::sim
