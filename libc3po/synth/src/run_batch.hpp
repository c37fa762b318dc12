#pragma once
// The synth layer's one batch path: generator items [begin, end) on
// `renderers.size()` workers, worker w taking begin + w, begin + w + W, ...
// with its own renderer. Each item has its own random stream, so what an item
// holds does not depend on the schedule; `consume` is called from the workers
// (it writes per-item slots or files). Stops early on an interrupt.
#include <cstddef>
#include <memory>
#include <vector>

#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/geometry/render.hpp"

namespace c3po {

// Generator: anything with Generate(std::size_t index, DepthRenderer*)
// (SynthGenerator, BopSceneGenerator).
template <typename Generator, typename Consume>
void RunBatch(const Generator& generator, std::size_t begin, std::size_t end,
              std::vector<std::unique_ptr<DepthRenderer>>& renderers, Consume consume) {
  const int workers = static_cast<int>(renderers.size());
  ParallelFor(
      0, workers,
      [&](int w) {
        for (std::size_t i = begin + static_cast<std::size_t>(w); i < end;
             i += static_cast<std::size_t>(workers)) {
          if (InterruptRequested()) return;
          consume(i, generator.Generate(i, renderers[static_cast<std::size_t>(w)].get()));
        }
      },
      workers);
}

}  // namespace c3po
