#include "test_certificates.h"

#include <fstream>

#include "shell_command.h"

namespace wircam::testing {

bool makeCertificates(const std::filesystem::path& folder) {
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "san.ext") << "subjectAltName=IP:127.0.0.1\n";
  return runCommand("cd '" + folder.string() +
                    "' && openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem "
                    "-days 2 -subj '/CN=wircam test CA' 2>/dev/null && "
                    "openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr "
                    "-subj '/CN=127.0.0.1' 2>/dev/null && "
                    "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial "
                    "-out server.pem -days 2 -extfile san.ext 2>/dev/null && "
                    // mosquitto, started as root, reads it as its own user.
                    "chmod 644 server.key")
             .exitCode == 0;
}

}  // namespace wircam::testing
