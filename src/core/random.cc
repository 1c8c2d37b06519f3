#include "lrcal/core/random.h"

#include <Random123/philox.h>

#include <Random123/boxmuller.hpp>
#include <Random123/uniform.hpp>

namespace lrcal {

void Philox4x64(const std::uint64_t counter[4], const std::uint64_t key[2], std::uint64_t out[4]) {
  r123::Philox4x64 rng;
  r123::Philox4x64::ctr_type c = {{counter[0], counter[1], counter[2], counter[3]}};
  r123::Philox4x64::key_type k = {{key[0], key[1]}};
  r123::Philox4x64::ctr_type r = rng(c, k);
  for (int i = 0; i < 4; ++i) out[i] = r[i];
}

void RandomStream::Block(std::uint64_t block, std::uint64_t out[4]) const {
  const std::uint64_t counter[4] = {trial_, purpose_, block, 0};
  const std::uint64_t key[2] = {seed_, stream_};
  Philox4x64(counter, key, out);
}

double RandomStream::Uniform(std::uint64_t index) const {
  std::uint64_t w[4];
  Block(index / 4, w);
  return r123::u01<double>(w[index % 4]);
}

double RandomStream::Normal(std::uint64_t index) const {
  std::uint64_t w[4];
  Block(index / 4, w);
  const int pair = static_cast<int>(index % 4) / 2;
  r123::double2 z = r123::boxmuller(w[2 * pair], w[2 * pair + 1]);
  return index % 2 == 0 ? z.x : z.y;
}

void RandomStream::Normals(std::uint64_t first, int count, double* out) const {
  int k = 0;
  while (k < count) {
    const std::uint64_t index = first + k;
    if (index % 4 != 0 || count - k < 4) {
      out[k++] = Normal(index);
      continue;
    }
    std::uint64_t w[4];
    Block(index / 4, w);
    r123::double2 a = r123::boxmuller(w[0], w[1]);
    r123::double2 b = r123::boxmuller(w[2], w[3]);
    out[k] = a.x;
    out[k + 1] = a.y;
    out[k + 2] = b.x;
    out[k + 3] = b.y;
    k += 4;
  }
}

}  // namespace lrcal
