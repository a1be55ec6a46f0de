// Prints rmw_zenoh's GID of each argument (a liveliness token), as hex: the vectors in
// test/runtime/test_runtime_wire.py come from this program built against rmw_zenoh's own hash.
//
//   R=<rmw_zenoh checkout>/rmw_zenoh_cpp/src/detail   (or the ros2-gbp release repository's src/detail)
//   g++ -O1 -I"$R" -o gid_vectors gid_vectors.cpp "$R/simplified_xxhash3.cpp" && ./gid_vectors TOKEN...
//
// Entity::Entity (liveliness_utils.cpp) copies low64 then high64 of simplified_XXH3_128bits(token)
// into the 16-byte GID on a little-endian machine; so does this.
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "simplified_xxhash3.hpp"

int main(int argc, char ** argv)
{
  for (int a = 1; a < argc; ++a) {
    const simplified_XXH128_hash_t hash = simplified_XXH3_128bits(argv[a], std::strlen(argv[a]));
    uint8_t gid[16];
    std::memcpy(gid, &hash.low64, sizeof(hash.low64));
    std::memcpy(gid + sizeof(hash.low64), &hash.high64, sizeof(hash.high64));
    for (const uint8_t byte : gid) {
      std::printf("%02x", byte);
    }
    std::printf("\n");
  }
  return 0;
}
