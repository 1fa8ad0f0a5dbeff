// hemilight/error.hpp — status codes, the exception the C++ API throws, and the version.
//
// Error policy: math kernels take validated data and assert their preconditions;
// functions that build objects from user data (scenes, cube maps, options, files) validate and
// throw hemilight::error with a status code and a message that names the bad argument. The C ABI
// catches every exception and turns it into a hemilight_status plus hemilight_last_error().
#pragma once

#include <stdexcept>
#include <string>

namespace hemilight {

/// Library version (semantic versioning). Matches hemilight_version() of the C ABI.
inline constexpr int version_major = 0;
inline constexpr int version_minor = 15;
inline constexpr int version_patch = 0;

/// The status codes of the C ABI, in the same order and with the same values.
enum class status : int {
  ok = 0,
  invalid_argument = 1,  ///< a NULL, NaN, out-of-range or inconsistent argument
  out_of_memory = 2,     ///< an allocation failed, or would exceed a documented limit or size_t
  io = 3,                ///< a file could not be opened, read, parsed or written
  unsupported = 4,       ///< valid input that this version does not handle (e.g. a channel set)
  cancelled = 5,         ///< a progress callback asked to stop
  internal = 6,          ///< a bug in hemilight: please report it
};

/// Human-readable name of a status code ("invalid argument", ...). Never NULL.
const char* status_name(status code) noexcept;

/// The exception thrown by hemilight's validating functions.
/// what() names the argument or file and the problem, e.g.
/// "read_exr: 'sky.exr': missing channel 'G' (file has R, B)".
class error : public std::runtime_error {
 public:
  error(status code, const std::string& message) : std::runtime_error(message), code_(code) {}
  status code() const noexcept { return code_; }

 private:
  status code_;
};

/// Throws error(status::invalid_argument, message) — a one-liner for validation code.
[[noreturn]] void throw_invalid_argument(const std::string& message);

}  // namespace hemilight
