// Status strings, the thread-local last-error message, and the mapping of
// C++ exceptions to statuses.
#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>

#include "internal.hpp"
#include "sogmm/error.hpp"

namespace {

// A fixed array rather than std::string: setting the message never
// allocates (so it cannot fail while reporting an out-of-memory error) and
// the storage needs no thread-exit destructor.
constexpr std::size_t kMessageCapacity = 1024;
thread_local char t_message[kMessageCapacity] = {0};

void store(const char* message) noexcept {
  if (!message) message = "";
  std::size_t n = std::strlen(message);
  if (n >= kMessageCapacity) n = kMessageCapacity - 1;
  std::memcpy(t_message, message, n);
  t_message[n] = '\0';
}

sogmm_status map_code(sogmm::ErrorCode code) noexcept {
  switch (code) {
    case sogmm::ErrorCode::InvalidArgument: return SOGMM_E_INVALID_ARG;
    case sogmm::ErrorCode::InvalidData: return SOGMM_E_INVALID_DATA;
    case sogmm::ErrorCode::Numeric: return SOGMM_E_NUMERIC;
    case sogmm::ErrorCode::Io: return SOGMM_E_IO;
    case sogmm::ErrorCode::Format: return SOGMM_E_FORMAT;
    case sogmm::ErrorCode::Limit: return SOGMM_E_LIMIT;
    case sogmm::ErrorCode::Cancelled: return SOGMM_E_CANCELLED;
  }
  return SOGMM_E_INTERNAL;
}

}  // namespace

namespace sogmm_capi {

void fail(sogmm_status status, const std::string& message) { throw StatusError{status, message}; }

void clear_error() noexcept { t_message[0] = '\0'; }

sogmm_status set_error(sogmm_status status, const char* message) noexcept {
  store(message);
  return status;
}

sogmm_status handle_current_exception() noexcept {
  try {
    throw;
  } catch (const StatusError& e) {
    return set_error(e.status, e.message.c_str());
  } catch (const sogmm::Error& e) {
    return set_error(map_code(e.code()), e.what());
  } catch (const std::bad_alloc&) {
    return set_error(SOGMM_E_NOMEM, "out of memory");
  } catch (const std::length_error& e) {
    // std::vector / std::string refusing a size beyond max_size().
    store("size limit exceeded: ");
    std::size_t used = std::strlen(t_message);
    std::strncat(t_message, e.what(), kMessageCapacity - used - 1);
    return SOGMM_E_LIMIT;
  } catch (const std::exception& e) {
    store("internal error: ");
    std::size_t used = std::strlen(t_message);
    std::strncat(t_message, e.what(), kMessageCapacity - used - 1);
    return SOGMM_E_INTERNAL;
  } catch (...) {
    return set_error(SOGMM_E_INTERNAL, "internal error: unknown exception");
  }
}

}  // namespace sogmm_capi

extern "C" {

SOGMM_API const char* sogmm_last_error(void) { return t_message; }

SOGMM_API const char* sogmm_status_string(sogmm_status status) {
  switch (status) {
    case SOGMM_OK: return "ok";
    case SOGMM_E_NULL_ARG: return "null pointer argument";
    case SOGMM_E_INVALID_ARG: return "invalid argument";
    case SOGMM_E_INVALID_DATA: return "invalid data";
    case SOGMM_E_NUMERIC: return "numerical failure";
    case SOGMM_E_IO: return "input/output error";
    case SOGMM_E_FORMAT: return "invalid or unsupported .sogmm format";
    case SOGMM_E_LIMIT: return "size limit exceeded";
    case SOGMM_E_NOMEM: return "out of memory";
    case SOGMM_E_BUFFER_TOO_SMALL: return "output buffer too small";
    case SOGMM_E_NOT_FOUND: return "not found";
    case SOGMM_E_INTERNAL: return "internal error";
    case SOGMM_E_CANCELLED: return "cancelled by the progress callback";
    case SOGMM_E_BUSY: return "map busy: another call is using it";
    default: return "unknown status";
  }
}

}  // extern "C"
