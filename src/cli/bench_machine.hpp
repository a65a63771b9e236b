#pragma once
// What a benchmark's figures were measured on. The force kernels and the cull run as many
// doubles at a time as the build's vector instructions hold (eight with AVX-512, four with
// AVX2, two with SSE2), so the same code gives figures far apart on two processors of
// similar clocks (the walking skirt's forces: 0.16 ms per frame with AVX-512, 0.27 with
// AVX2; docs/PERFORMANCE.md): the figures say which they came from.

#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace drape::cli {

/// The widest vector instructions this build was compiled for (-march).
[[nodiscard]] inline const char* buildVectorIsa() {
#if defined(__AVX512F__)
  return "AVX-512";
#elif defined(__AVX2__)
  return "AVX2";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__SSE2__)
  return "SSE2";
#else
  return "none";
#endif
}

/// The widest of those vector instructions the processor running it has.
[[nodiscard]] inline const char* cpuVectorIsa() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return "AVX-512";
  if (__builtin_cpu_supports("avx2")) return "AVX2";
  if (__builtin_cpu_supports("avx")) return "AVX";
  if (__builtin_cpu_supports("sse2")) return "SSE2";
#endif
  return "none";
}

/// The processor's model name as Linux reports it, or "unknown".
[[nodiscard]] inline std::string cpuModelName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
    }
  return "unknown";
}

/// {"cpu", "cpu_vector_isa", "build_vector_isa"} for a benchmark's JSON.
[[nodiscard]] inline nlohmann::json benchMachine() {
  return {{"cpu", cpuModelName()}, {"cpu_vector_isa", cpuVectorIsa()}, {"build_vector_isa", buildVectorIsa()}};
}

}  // namespace drape::cli
