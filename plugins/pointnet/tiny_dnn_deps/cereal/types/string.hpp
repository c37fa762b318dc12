#pragma once
// See cereal/cereal.hpp: declarations only, for tiny-dnn's headers.
#include "../cereal.hpp"
