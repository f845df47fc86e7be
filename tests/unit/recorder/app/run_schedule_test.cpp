// RunSchedule: what a recorder run does on time, with time passed in.
#include "app/run_schedule.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using Clock = RunSchedule::Clock;
const Clock::time_point kStart = Clock::time_point() + std::chrono::hours(1);

RunPeriods onlyStatus() {
  // The camera tick and retention as far off as can be: out of the way.
  return {.status = seconds(1),
          .cameraTick = std::chrono::hours(24),
          .retention = std::chrono::hours(24)};
}

TEST(RunSchedule, EndsOnceAtItsDurationAndNotBefore) {
  RunPeriods periods = onlyStatus();
  periods.duration = milliseconds(2500);
  RunSchedule schedule(periods, kStart);
  EXPECT_EQ(schedule.due(kStart + milliseconds(2499)), std::vector<RunJob>{RunJob::Status});
  EXPECT_EQ(schedule.next(), kStart + milliseconds(2500));
  EXPECT_EQ(schedule.due(kStart + milliseconds(2500)), std::vector<RunJob>{RunJob::End});
  EXPECT_EQ(schedule.due(kStart + seconds(5)), std::vector<RunJob>{RunJob::Status});
  EXPECT_EQ(schedule.next(), kStart + seconds(6));
}

TEST(RunSchedule, ALateLookRunsAJobOnceAndKeepsItOnItsGrid) {
  RunSchedule schedule(onlyStatus(), kStart);
  EXPECT_EQ(schedule.next(), kStart + seconds(1));
  // The machine was busy for 2.7 s: one status, not three, and the next on
  // the whole second, not 1 s after this late one.
  EXPECT_EQ(schedule.due(kStart + milliseconds(3700)), std::vector<RunJob>{RunJob::Status});
  EXPECT_EQ(schedule.next(), kStart + seconds(4));
  EXPECT_EQ(schedule.due(kStart + milliseconds(3999)), std::vector<RunJob>{});
  EXPECT_EQ(schedule.due(kStart + seconds(4)), std::vector<RunJob>{RunJob::Status});
}

TEST(RunSchedule, RunsOnlyTheJobsItsOptionsAskForInOneOrder) {
  RunPeriods plain;  // no MQTT, no Foxglove, no --duration
  RunSchedule schedule(plain, kStart);
  std::vector<RunJob> seen;
  for (auto t = kStart; t <= kStart + seconds(61); t += milliseconds(50))
    for (RunJob job : schedule.due(t)) seen.push_back(job);
  for (RunJob never : {RunJob::End, RunJob::FleetStatus, RunJob::FoxgloveStatus, RunJob::Snapshots,
                       RunJob::StopBackstop})
    EXPECT_EQ(std::count(seen.begin(), seen.end(), never), 0) << static_cast<int>(never);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), RunJob::Status), 61);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), RunJob::CameraTick), 244);  // every 250 ms
  EXPECT_EQ(std::count(seen.begin(), seen.end(), RunJob::Retention), 1);

  RunPeriods fleet;
  fleet.fleetStatus = fleet.foxgloveStatus = fleet.snapshots = seconds(1);
  RunSchedule all(fleet, kStart);
  EXPECT_EQ(all.due(kStart + seconds(1)),
            (std::vector<RunJob>{RunJob::Status, RunJob::CameraTick, RunJob::FleetStatus,
                                 RunJob::FoxgloveStatus, RunJob::Snapshots}));
}

TEST(RunSchedule, AStopArmsItsBackstopOnceAndTheRestGoesOn) {
  RunSchedule schedule(onlyStatus(), kStart);
  schedule.stopping(kStart + milliseconds(100), milliseconds(2900));
  schedule.stopping(kStart + milliseconds(900), milliseconds(2900));  // the first one holds
  EXPECT_EQ(schedule.due(kStart + seconds(1)), std::vector<RunJob>{RunJob::Status});
  EXPECT_EQ(schedule.due(kStart + seconds(3)),
            (std::vector<RunJob>{RunJob::Status, RunJob::StopBackstop}));
  EXPECT_EQ(schedule.next(), kStart + seconds(4));
}

TEST(RunSchedule, AZeroPeriodIsAMillisecondNotAJobDueAtEveryLook) {
  RunPeriods periods = onlyStatus();
  periods.status = milliseconds(0);
  RunSchedule schedule(periods, kStart);
  EXPECT_EQ(schedule.next(), kStart + milliseconds(1));
  EXPECT_EQ(schedule.due(kStart + milliseconds(1)), std::vector<RunJob>{RunJob::Status});
  EXPECT_EQ(schedule.due(kStart + milliseconds(1)), std::vector<RunJob>{});
}

}  // namespace
}  // namespace wircam::recorder
