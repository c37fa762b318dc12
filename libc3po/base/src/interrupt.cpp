#include "c3po/base/interrupt.hpp"

#include <atomic>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {
std::atomic<bool> g_interrupt_requested{false};
}

void RequestInterrupt() { g_interrupt_requested.store(true); }
bool InterruptRequested() { return g_interrupt_requested.load(); }
void ClearInterrupt() { g_interrupt_requested.store(false); }
void ThrowIfInterrupted() {
  if (InterruptRequested()) throw Interrupted();
}

}  // namespace c3po
