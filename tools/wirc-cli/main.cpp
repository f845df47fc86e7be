// wirc-cli: talk to a WiRC device (or wirc-sim) from a shell.
#include <cstdio>
#include <cstring>
#include <string_view>

namespace {

constexpr const char* kUsage = R"(Usage: wirc-cli COMMAND [OPTIONS]

Talk to a WiRC device or wirc-sim from the shell.

Commands:
  help            show this text

Exit codes: 0 success, 1 failure, 2 bad usage.
)";

}  // namespace

int main(int argc, char** argv) {
  std::string_view command = argc > 1 ? argv[1] : "help";
  if (command == "help" || command == "--help" || command == "-h") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  std::fprintf(stderr, "wirc-cli: unknown command '%s' (see wirc-cli --help)\n", argv[1]);
  return 2;
}
