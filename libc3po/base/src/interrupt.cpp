#include "c3po/base/interrupt.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

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

void HoldForInterruptAt(int epoch, long long batch) {
  const char* spec = std::getenv("C3PO_TEST_HOLD_AT");
  if (spec == nullptr) return;
  int hold_epoch = 0;
  long long hold_batch = 0;
  if (std::sscanf(spec, "%d:%lld", &hold_epoch, &hold_batch) != 2) return;
  if (hold_epoch != epoch || hold_batch != batch) return;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!InterruptRequested() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace c3po
