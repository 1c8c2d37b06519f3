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

double NormalDraws::operator()(std::uint64_t index) {
  const std::uint64_t pair = index / 2;
  if (!have_pair_ || pair != pair_) {
    if (!have_block_ || index / 4 != block_) {
      stream_.Block(index / 4, words_);
      block_ = index / 4;
      have_block_ = true;
    }
    const int k = static_cast<int>(index % 4) / 2;
    const r123::double2 z = r123::boxmuller(words_[2 * k], words_[2 * k + 1]);
    z_[0] = z.x;
    z_[1] = z.y;
    pair_ = pair;
    have_pair_ = true;
  }
  return z_[index % 2];
}

void RandomStream::Normals(std::uint64_t first, int count, double* out) const {
  NormalDraws draws(*this);
  for (int k = 0; k < count; ++k) out[k] = draws(first + static_cast<std::uint64_t>(k));
}

}  // namespace lrcal
