#pragma once

#include "core/config/scada_config.hpp"
#include "core/config/section.hpp"

namespace icewatch::config {

// Reads and validates the "scada" section.
void readScada(Section s, ScadaConfig& scada);

}  // namespace icewatch::config
