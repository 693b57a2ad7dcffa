#pragma once
// Memory limits for work whose size comes from the input (image pixels, point counts, frames):
// such work is refused before it allocates, with a message that says how much it needs and how
// much the machine has, instead of being killed by the kernel or ending in std::bad_alloc.
#include <cstdint>
#include <string>

namespace kartograf {

// Bytes this process may still allocate: KARTOGRAF_MEMORY_LIMIT when set (bytes, or a number with
// a K, M or G suffix, powers of 1024: "512M"), else the kernel's MemAvailable (/proc/meminfo), and
// never more than the address-space limit (ulimit -v). Throws Error naming the variable when its
// value is not such a size.
std::uint64_t available_memory_bytes();

// Throws Error "<what> needs about <N>, <M> available" when `bytes` exceeds
// available_memory_bytes(). `bytes` is a double so that products of input sizes cannot overflow.
void require_fits_in_memory(double bytes, const std::string& what);

// "1.5 GB", "12.0 MB", "800 kB" (powers of 1024), for messages.
std::string memory_size_text(double bytes);

}  // namespace kartograf
