#pragma once
// Test certificates for the TLS tests, made with the `openssl` program as a user
// would make one: a self-signed P-256 certificate valid for a day, with the subject alternative
// names given. `openssl` comes from scripts/setup.sh.
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "tests/test_util.h"

namespace isowall::test {

struct TestCert {
    std::string cert, key;  // PEM files
};

// Makes NAME.crt and NAME.key in `dir`; throws with openssl's words when it fails.
inline TestCert make_test_cert(const std::filesystem::path& dir, const std::string& name,
                               const std::string& san = "DNS:localhost,IP:127.0.0.1") {
    const TestCert c{(dir / (name + ".crt")).string(), (dir / (name + ".key")).string()};
    const std::string log = (dir / (name + ".openssl.log")).string();
    const std::string cmd =
        "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 "
        "-subj /CN=" +
        name + " -addext subjectAltName=" + san + " -keyout '" + c.key + "' -out '" + c.cert +
        "' > '" + log + "' 2>&1";
    if (std::system(cmd.c_str()) != 0)
        throw std::runtime_error("openssl could not make a test certificate: " + slurp(log));
    return c;
}

}  // namespace isowall::test
