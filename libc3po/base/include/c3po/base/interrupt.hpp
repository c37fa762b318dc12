#pragma once
// Cooperative interruption: the CLI's SIGINT/SIGTERM handler calls
// RequestInterrupt(); long library loops call ThrowIfInterrupted() between
// steps (after a checkpoint is safe), which throws c3po::Interrupted.
namespace c3po {

void RequestInterrupt();
bool InterruptRequested();
void ClearInterrupt();
void ThrowIfInterrupted();

}  // namespace c3po
