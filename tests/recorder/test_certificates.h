// Certificates for the TLS tests, made by openssl in a folder: a CA
// (ca.pem, ca.key) and a server certificate for 127.0.0.1 it signed
// (server.pem, server.key).
#pragma once

#include <filesystem>

namespace wircam::testing {

bool makeCertificates(const std::filesystem::path& folder);

}  // namespace wircam::testing
