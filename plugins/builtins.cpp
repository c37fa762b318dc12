// The detectors compiled into c3po.
#include "registry_internal.hpp"

namespace c3po {

void RegisterBuiltinDetectors() {}

}  // namespace c3po
