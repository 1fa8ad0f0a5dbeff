#include "hemilight/error.hpp"

namespace hemilight {

const char* status_name(status code) noexcept {
  switch (code) {
    case status::ok: return "ok";
    case status::invalid_argument: return "invalid argument";
    case status::out_of_memory: return "out of memory";
    case status::io: return "I/O error";
    case status::unsupported: return "unsupported";
    case status::cancelled: return "cancelled";
    case status::internal: return "internal error";
  }
  return "unknown status";
}

void throw_invalid_argument(const std::string& message) {
  throw error(status::invalid_argument, message);
}

}  // namespace hemilight
