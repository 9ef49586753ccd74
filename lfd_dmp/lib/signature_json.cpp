#include "lfd_dmp/signature_json.hpp"

#include "json_fields.hpp"

namespace lfd_dmp {
namespace {

using nlohmann::json;
using namespace json_fields;

json optionsJson(const lfd::SignatureOptions& o) {
  return {{"phase_bins", o.phase_bins},
          {"phase_slack", o.phase_slack},
          {"time_slack", o.time_slack},
          {"persistence", o.persistence},
          {"min_spread_fraction", o.min_spread_fraction},
          {"noise_sigmas", o.noise_sigmas},
          {"threshold_margin", o.threshold_margin},
          {"min_threshold", o.min_threshold},
          {"rest_band_fraction", o.rest_band_fraction}};
}

double nonNegative(const json& j, const char* key, const std::string& where) {
  const double v = number(member(j, key, where), where + "." + key);
  if (v < 0) fail(where + "." + key, "must be >= 0");
  return v;
}

lfd::SignatureOptions optionsFromJson(const json& j, const std::string& w) {
  lfd::SignatureOptions o;
  const double bins = number(member(j, "phase_bins", w), w + ".phase_bins");
  if (bins != std::floor(bins) || !(bins >= 0 && bins <= 1e6))
    fail(w + ".phase_bins", "must be a whole number");
  o.phase_bins = static_cast<std::size_t>(bins);
  o.phase_slack = number(member(j, "phase_slack", w), w + ".phase_slack");
  o.time_slack = number(member(j, "time_slack", w), w + ".time_slack");
  o.persistence = number(member(j, "persistence", w), w + ".persistence");
  o.min_spread_fraction = number(member(j, "min_spread_fraction", w), w + ".min_spread_fraction");
  o.noise_sigmas = number(member(j, "noise_sigmas", w), w + ".noise_sigmas");
  o.threshold_margin = number(member(j, "threshold_margin", w), w + ".threshold_margin");
  o.min_threshold = number(member(j, "min_threshold", w), w + ".min_threshold");
  // A library learned before the missing-contact check has none.
  o.rest_band_fraction = j.contains("rest_band_fraction")
                             ? number(j["rest_band_fraction"], w + ".rest_band_fraction")
                             : 0.0;
  try {
    lfd::checkSignatureOptions(o);  // the learner's own rule, one place
  } catch (const std::invalid_argument& e) {
    fail(w, e.what());
  }
  return o;
}

lfd::ChannelSignature channelFromJson(const json& j, std::size_t bins, const std::string& w) {
  lfd::ChannelSignature c;
  c.mean = vector(member(j, "mean", w), w + ".mean", static_cast<long>(bins));
  c.spread = vector(member(j, "spread", w), w + ".spread", static_cast<long>(bins));
  if (!(c.spread.minCoeff() > 0)) fail(w + ".spread", "every spread must be > 0");
  c.threshold = number(member(j, "threshold", w), w + ".threshold");
  if (!(c.threshold > 0)) fail(w + ".threshold", "must be > 0");
  c.nominal_score = nonNegative(j, "nominal_score", w);
  if (j.contains("held")) {
    c.held = vector(j["held"], w + ".held", static_cast<long>(bins));
    if (!(c.held.minCoeff() >= 0)) fail(w + ".held", "every distance must be >= 0");
  }
  return c;
}

}  // namespace

json toJson(const lfd::SensorySignature& signature) {
  json segments = json::array();
  for (const lfd::SegmentSignature& s : signature.segments) {
    json channels = json::array();
    for (const lfd::ChannelSignature& c : s.channels) {
      json channel = {{"mean", vectorJson(c.mean)},
                      {"spread", vectorJson(c.spread)},
                      {"threshold", c.threshold},
                      {"nominal_score", c.nominal_score}};
      if (c.held.size() > 0) channel["held"] = vectorJson(c.held);
      channels.push_back(channel);
    }
    segments.push_back({{"duration_mean", s.duration_mean},
                        {"duration_spread", s.duration_spread},
                        {"channels", channels}});
  }
  return {{"channels", signature.channels},
          {"sources", signature.sources},
          {"demonstrations", signature.demonstrations},
          {"options", optionsJson(signature.options)},
          {"rest_bands", signature.rest_bands},
          {"segments", segments}};
}

lfd::SensorySignature signatureFromJson(const json& j, const std::string& where) {
  lfd::SensorySignature sig;
  sig.channels = texts(member(j, "channels", where), where + ".channels");
  if (sig.channels.empty()) fail(where + ".channels", "needs at least one channel");
  sig.sources = texts(member(j, "sources", where), where + ".sources");
  if (!sig.sources.empty() && sig.sources.size() != sig.channels.size())
    fail(where + ".sources", "one source per channel (or none)");
  sig.demonstrations = static_cast<std::size_t>(nonNegative(j, "demonstrations", where));
  sig.options = optionsFromJson(member(j, "options", where), where + ".options");
  if (j.contains("rest_bands")) {
    const Eigen::VectorXd bands = vector(j["rest_bands"], where + ".rest_bands");
    if (bands.size() != 0 && bands.size() != static_cast<Eigen::Index>(sig.channels.size()))
      fail(where + ".rest_bands", "one band per channel (or none)");
    if (bands.size() != 0 && !(bands.minCoeff() >= 0))
      fail(where + ".rest_bands", "every band must be >= 0");
    sig.rest_bands.assign(bands.data(), bands.data() + bands.size());
  }
  const json& segments = member(j, "segments", where);
  if (!segments.is_array() || segments.empty())
    fail(where + ".segments", "expected a non-empty array");
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const std::string ws = where + ".segments[" + std::to_string(s) + "]";
    lfd::SegmentSignature seg;
    seg.duration_mean = nonNegative(segments[s], "duration_mean", ws);
    seg.duration_spread = nonNegative(segments[s], "duration_spread", ws);
    const json& channels = member(segments[s], "channels", ws);
    if (!channels.is_array() || channels.size() != sig.channels.size())
      fail(ws + ".channels",
           "expected one entry per channel (" + std::to_string(sig.channels.size()) + ")");
    for (std::size_t c = 0; c < channels.size(); ++c)
      seg.channels.push_back(channelFromJson(channels[c], sig.options.phase_bins,
                                             ws + ".channels[" + std::to_string(c) + "]"));
    sig.segments.push_back(std::move(seg));
  }
  return sig;
}

}  // namespace lfd_dmp
