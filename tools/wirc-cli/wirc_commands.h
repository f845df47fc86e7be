// wirc-cli's commands for a WiRC device. Each takes the parsed command
// line, prints what came of it and returns the exit code (a failure or bad
// usage exits through fail() or usageError()).
#pragma once

#include "cli_options.h"

namespace wircam::cli {

int discover(const Options& o);
int info(const Options& o);
int transmitters(const Options& o);
int requestControl(const Options& o);  // ID: the connection to give it to
int configure(const Options& o);
int setName(const Options& o);  // NAME
int extout(const Options& o);
int firmwareUpdate(const Options& o);
int wifi(const Options& o);
int stream(const Options& o);
int drive(const Options& o);
int decode(const Options& o);
int encode(const Options& o);

}  // namespace wircam::cli
