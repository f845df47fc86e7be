// What the option table's rows are made of (the options room's own): the
// readers of the common kinds of value, each checking its range and saying
// it the same way, and the sections the documentation heads.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/option_table.h"

namespace wircam::recorder::option_rows {

using Apply = std::function<OptionProblem(RecorderOptions&, const char*)>;

Apply seconds(double RecorderOptions::*field, double low, double high);
Apply wholeNumber(unsigned RecorderOptions::*field, double low, double high, const char* unit);
Apply onOff(bool RecorderOptions::*field);
Apply text(std::string RecorderOptions::*field);
Apply optionalText(std::optional<std::string> RecorderOptions::*field);
Apply serverAddress(std::optional<ServerAddress> RecorderOptions::*field);
Apply size(uint64_t RecorderOptions::*field);
Apply duration(std::chrono::seconds RecorderOptions::*field);
// --periods (CCFG) or --failsafe (FCFG), as the device would take them.
Apply channels(std::optional<std::string> RecorderOptions::*field, bool periods);
// A topic prefix: no wildcards, no empty level at either end.
OptionProblem topicPrefix(const std::string& prefix, const char* example);
// --on-segment-closed: split as a shell would.
OptionProblem commandLine(RecorderOptions& o, const char* value);
// A flag's value in the config file (the command line's flag says true).
std::optional<bool> trueOrFalse(const char* value);

inline constexpr const char* kDevices = "Devices and cameras";
inline constexpr const char* kFiles = "Files";
inline constexpr const char* kRetention = "Retention";
inline constexpr const char* kDetection = "Detection and following";
inline constexpr const char* kWeb = "Web server";
inline constexpr const char* kFoxglove = "Foxglove";
inline constexpr const char* kFleet = "MQTT and hooks";
inline constexpr const char* kOther = "Other";

// The rows of each part of the table (server_options.cpp: the web,
// Foxglove, MQTT and hook options; device_keys.cpp: [device NAME]'s keys).
std::vector<OptionSpec> serverOptionRows();
std::vector<DeviceKeySpec> deviceKeyRows();

}  // namespace wircam::recorder::option_rows
