#pragma once
// Plain-data serialisation across the process boundary (core/isolate.hpp): what a reader's
// child writes to its pipe and drape reads back, checked against truncation.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::formats::detail {

template <typename T>
void put(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
void putVector(std::string& s, const std::vector<T>& v) {
  put<std::uint64_t>(s, v.size());
  if (!v.empty()) s.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

inline void putStrings(std::string& s, const std::vector<std::string>& strings) {
  put<std::uint64_t>(s, strings.size());
  for (const std::string& x : strings) putVector(s, std::vector<char>(x.begin(), x.end()));
}

struct Cursor {
  std::string_view bytes;
  std::size_t at = 0;
  std::string name;
  template <typename T>
  T get() {
    if (bytes.size() - at < sizeof(T)) throw Error(fmt::format("{}: the reader returned truncated data", name));
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <typename T>
  std::vector<T> getVector() {
    const auto n = get<std::uint64_t>();
    if (n > (bytes.size() - at) / std::max<std::size_t>(sizeof(T), 1)) throw Error(fmt::format("{}: the reader returned truncated data", name));
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), bytes.data() + at, n * sizeof(T));  // an empty vector's data() may be null
    at += n * sizeof(T);
    return v;
  }
  /// A list putStrings wrote; `most` bounds its length (bad data otherwise).
  std::vector<std::string> getStrings(std::size_t most = 1'000'000) {
    const auto n = get<std::uint64_t>();
    if (n > most || n > bytes.size() - at) throw Error(fmt::format("{}: the reader returned bad data", name));
    std::vector<std::string> out;
    out.reserve(n);
    for (std::uint64_t k = 0; k < n; ++k) {
      const std::vector<char> chars = getVector<char>();
      out.emplace_back(chars.begin(), chars.end());
    }
    return out;
  }
};

}  // namespace drape::formats::detail
