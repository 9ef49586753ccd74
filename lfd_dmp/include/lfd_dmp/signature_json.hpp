// The sensory signature (lfd_core/dmp/sensory_signature.hpp) as JSON, stored with the skill library
// under "sensory_signature": what each segment's sensors showed in the demonstrations, for the
// executor's live monitoring.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "lfd_core/dmp/sensory_signature.hpp"

namespace lfd_dmp {

nlohmann::json toJson(const lfd::SensorySignature& signature);

/// Throws std::runtime_error "<where>...: ..." for a missing or malformed field, a spread or
/// threshold that is not > 0, or arrays whose lengths disagree (phase_bins, channels).
lfd::SensorySignature signatureFromJson(const nlohmann::json& j, const std::string& where);

}  // namespace lfd_dmp
