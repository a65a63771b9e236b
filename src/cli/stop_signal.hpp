#pragma once
// SIGINT and SIGTERM asking a studio role to stop where it is, so that it closes what it is
// doing (a live take's End, a recording's files) instead of dying in the middle of it.

#include <atomic>
#include <csignal>

namespace drape::cli {

namespace detail {
inline std::atomic<bool> stopAsked{false};
extern "C" inline void askToStop(int) { stopAsked = true; }
}  // namespace detail

/// Installs the handlers and returns the flag they set (lock-free, so a handler may set it).
inline const std::atomic<bool>& stopOnSignals() {
  static_assert(std::atomic<bool>::is_always_lock_free);
  std::signal(SIGINT, detail::askToStop);
  std::signal(SIGTERM, detail::askToStop);
  return detail::stopAsked;
}

/// Sets the flag as a signal would: what waits on it (a live source) stops (a window that
/// closed, say).
inline void askToStop() { detail::stopAsked = true; }

}  // namespace drape::cli
