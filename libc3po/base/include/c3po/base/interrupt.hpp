#pragma once
// Cooperative interruption: the CLI's SIGINT/SIGTERM handler calls
// RequestInterrupt(); long library loops call ThrowIfInterrupted() between
// steps (after a checkpoint is safe), which throws c3po::Interrupted.
namespace c3po {

void RequestInterrupt();
bool InterruptRequested();
void ClearInterrupt();
void ThrowIfInterrupted();

// Test hook that makes interruption tests independent of timing: when the
// environment variable C3PO_TEST_HOLD_AT is "E:B", a training loop calling
// HoldForInterruptAt(E, B) before batch B of epoch E waits there until an
// interrupt is requested (at most 120 s), so a signal sent at any moment
// after epoch E-1 was reported lands inside epoch E, never after the run
// has finished. Without the variable (or at any other step) it returns at once.
void HoldForInterruptAt(int epoch, long long batch);

}  // namespace c3po
