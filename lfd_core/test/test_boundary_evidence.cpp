// The pieces of boundary evidence the joint segmentation weighs (boundary_evidence.hpp): the
// speed of the state features, its pauses, motion onsets and stops, and the sensory evidence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lfd_core/segmentation/boundary_evidence.hpp"

namespace {

constexpr double kRate = 50.0;

// Minimum-jerk position profile from 0 to 1 (tau in [0, 1]).
double minJerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

// A one-coordinate motion made of pieces: a move of `way` over `seconds` (min-jerk), or a rest
// (way 0). Sampled at 50 Hz from t = 0.
struct Piece {
  double seconds = 0.0;
  double way = 0.0;
};

struct Motion {
  std::vector<double> time;
  Eigen::MatrixXd states;      // one column
  std::vector<double> starts;  // start time of each piece
};

Motion makeMotion(const std::vector<Piece>& pieces) {
  Motion m;
  double total = 0.0;
  for (const Piece& p : pieces) {
    m.starts.push_back(total);
    total += p.seconds;
  }
  const int n = static_cast<int>(std::lround(total * kRate)) + 1;
  m.states.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    const double t = i / kRate;
    m.time.push_back(t);
    double x = 0.0;
    for (std::size_t k = 0; k < pieces.size(); ++k)
      if (pieces[k].way != 0.0) x += pieces[k].way * minJerk((t - m.starts[k]) / pieces[k].seconds);
    m.states(i, 0) = x;
  }
  return m;
}

Eigen::VectorXd speedOf(const Motion& m) {
  return lfd::stateSpeed(m.states, m.time, lfd::PauseConfig{}.smoothing);
}

std::size_t sampleAt(double t) {
  return static_cast<std::size_t>(std::lround(t * kRate));
}

std::vector<lfd::Pause> interior(const std::vector<lfd::Pause>& pauses, std::size_t n) {
  std::vector<lfd::Pause> out;
  for (const lfd::Pause& p : pauses)
    if (p.begin > 0 && p.end < n) out.push_back(p);
  return out;
}

// ---- stateSpeed

TEST(StateSpeed, IsNearZeroAtRestAndPeaksMidMove) {
  // 1 s rest, a 2 s min-jerk move of 1, 1 s rest: peak speed 1.875 / 2 at t = 2 s.
  const Motion m = makeMotion({{1.0, 0.0}, {2.0, 1.0}, {1.0, 0.0}});
  const Eigen::VectorXd speed = speedOf(m);
  ASSERT_EQ(speed.size(), m.states.rows());
  Eigen::Index peak = 0;
  const double top = speed.maxCoeff(&peak);
  EXPECT_NEAR(m.time[static_cast<std::size_t>(peak)], 2.0, 0.05);
  EXPECT_NEAR(top, 1.875 / 2.0, 0.05 * 1.875 / 2.0);
  EXPECT_LT(speed[static_cast<Eigen::Index>(sampleAt(0.5))], 1e-3 * top);
  EXPECT_LT(speed[static_cast<Eigen::Index>(sampleAt(3.5))], 1e-3 * top);
  EXPECT_GE(speed.minCoeff(), 0.0);
}

TEST(StateSpeed, ThrowsWhenTimestampsAndSamplesDiffer) {
  const Motion m = makeMotion({{1.0, 1.0}});
  std::vector<double> short_clock(m.time.begin(), m.time.end() - 1);
  EXPECT_THROW(lfd::stateSpeed(m.states, short_clock, 0.1), std::invalid_argument);
}

// ---- findPauses

TEST(FindPauses, ReportsTheRestBetweenTwoMovesEndingWhereMotionResumes) {
  // rest 1 s, move 2 s, rest 2 s, move 2 s, rest 1 s: the second move starts at 5 s.
  const Motion m = makeMotion({{1.0, 0.0}, {2.0, 1.0}, {2.0, 0.0}, {2.0, -1.0}, {1.0, 0.0}});
  const std::size_t n = m.time.size();
  const auto pauses = lfd::findPauses(speedOf(m), m.time, lfd::PauseConfig{});
  const auto inside = interior(pauses, n);
  ASSERT_EQ(inside.size(), 1u);
  const double begin = m.time[inside[0].begin], end = m.time[inside[0].end];
  EXPECT_NEAR(end, 5.0, 0.15) << "the pause ends where the second move starts";
  EXPECT_NEAR(begin, 3.0, 0.15) << "the pause begins where the first move ends";
  EXPECT_NEAR(end - begin, 2.0, 0.3);
}

TEST(FindPauses, ReportsTheFirstAndLastRestsAtTheDemosEnds) {
  const Motion m = makeMotion({{1.0, 0.0}, {2.0, 1.0}, {2.0, 0.0}, {2.0, -1.0}, {1.0, 0.0}});
  const std::size_t n = m.time.size();
  const auto pauses = lfd::findPauses(speedOf(m), m.time, lfd::PauseConfig{});
  ASSERT_EQ(pauses.size(), 3u);
  EXPECT_EQ(pauses.front().begin, 0u);
  EXPECT_NEAR(m.time[pauses.front().end], 1.0, 0.15);
  EXPECT_EQ(pauses.back().end, n);
  EXPECT_NEAR(m.time[pauses.back().begin], 7.0, 0.15);
}

// Two 1 s moves of 1 with `dip` s of rest between them, the second going on (`way` 1) or back
// (`way` -1), between 1 s rests.
Motion twoMoves(double dip, double way) {
  return makeMotion({{1.0, 0.0}, {1.0, 1.0}, {dip, 0.0}, {1.0, way}, {1.0, 0.0}});
}

TEST(FindPauses, AShortDipBetweenTwoMovesIsNoPause) {
  // A reversal with 0.1 s of rest, and a move that goes on after 0.2 s of rest: both shorter
  // than min_pause (0.25 s).
  for (const Motion& m : {twoMoves(0.1, -1.0), twoMoves(0.2, 1.0)}) {
    const auto pauses = lfd::findPauses(speedOf(m), m.time, lfd::PauseConfig{});
    EXPECT_TRUE(interior(pauses, m.time.size()).empty());
    EXPECT_EQ(pauses.size(), 2u) << "only the first and the last rest";
  }
}

// ---- motionOnsetEvidence

// Weight of the one onset after an interior pause of `pause` seconds between two moves.
std::vector<lfd::BoundaryEvidence> onsetsAfterPause(double pause, double weight,
                                                    std::vector<double>* time = nullptr) {
  const Motion m = makeMotion({{1.0, 0.0}, {2.0, 1.0}, {pause, 0.0}, {2.0, -1.0}, {1.0, 0.0}});
  const Eigen::VectorXd speed = speedOf(m);
  const lfd::PauseConfig config;
  const auto pauses = lfd::findPauses(speed, m.time, config);
  if (time) *time = m.time;
  return lfd::motionOnsetEvidence(speed, m.time, pauses, config, weight);
}

TEST(MotionOnsetEvidence, ALongerPauseWeighsMore) {
  std::vector<double> time;
  const auto long_pause = onsetsAfterPause(3.0, 0.8, &time);
  ASSERT_EQ(long_pause.size(), 1u);
  EXPECT_EQ(long_pause[0].kind, lfd::EvidenceKind::kMotionOnset);
  EXPECT_NEAR(time[long_pause[0].index], 6.0, 0.15) << "where the second move starts";
  const auto short_pause = onsetsAfterPause(0.5, 0.8);
  ASSERT_EQ(short_pause.size(), 1u);
  EXPECT_GT(long_pause[0].weight, short_pause[0].weight);
  EXPECT_GT(short_pause[0].weight, 0.0);
  EXPECT_LE(long_pause[0].weight, 0.8);
  // 1 - exp(-3 / 1) of a fast motion: nearly the full weight.
  EXPECT_GT(long_pause[0].weight, 0.8 * (1.0 - std::exp(-2.5)));
}

TEST(MotionOnsetEvidence, TheDemosFirstMotionIsNoEvidence) {
  // One move between the two end rests: the motion starts from the first rest only.
  const Motion m = makeMotion({{1.5, 0.0}, {2.0, 1.0}, {1.5, 0.0}});
  const Eigen::VectorXd speed = speedOf(m);
  const lfd::PauseConfig config;
  const auto pauses = lfd::findPauses(speed, m.time, config);
  ASSERT_EQ(pauses.size(), 2u);
  EXPECT_TRUE(lfd::motionOnsetEvidence(speed, m.time, pauses, config, 0.8).empty());
}

// ---- motionStopEvidence

// The one stop of `m`, at the slowest sample between the two moves' peaks (1.5 s and, with a
// dip of `dip` s, 2.5 + dip s).
void expectOneStopAtTheSpeedMinimum(const Motion& m, double dip) {
  const Eigen::VectorXd speed = speedOf(m);
  const auto stops = lfd::motionStopEvidence(speed, m.time, lfd::PauseConfig{}, 0.3);
  ASSERT_EQ(stops.size(), 1u);
  EXPECT_EQ(stops[0].kind, lfd::EvidenceKind::kMotionStop);
  EXPECT_DOUBLE_EQ(stops[0].weight, 0.3);
  const Eigen::Index from = static_cast<Eigen::Index>(sampleAt(1.5));
  Eigen::Index slowest = 0;
  speed.segment(from, static_cast<Eigen::Index>(sampleAt(2.5 + dip)) - from).minCoeff(&slowest);
  EXPECT_EQ(stops[0].index, static_cast<std::size_t>(from + slowest));
  EXPECT_NEAR(m.time[stops[0].index], 2.0 + 0.5 * dip, 0.1);
}

TEST(MotionStopEvidence, AReversalIsOnePieceAtTheSpeedMinimum) {
  expectOneStopAtTheSpeedMinimum(twoMoves(0.0, -1.0), 0.0);
  expectOneStopAtTheSpeedMinimum(twoMoves(0.1, -1.0), 0.1);
}

TEST(MotionStopEvidence, AnInstantOfRestBetweenTwoMovesIsOnePieceAtTheSpeedMinimum) {
  expectOneStopAtTheSpeedMinimum(twoMoves(0.2, 1.0), 0.2);
}

TEST(MotionStopEvidence, APauseIsNoStop) {
  const Motion m = twoMoves(2.0, 1.0);
  EXPECT_TRUE(lfd::motionStopEvidence(speedOf(m), m.time, lfd::PauseConfig{}, 0.3).empty());
}

// ---- gatherIntoPauses

TEST(GatherIntoPauses, EvidenceInsideAnInteriorPauseMovesToItsEnd) {
  const std::vector<lfd::Pause> pauses = {{0, 50}, {200, 300}, {400, 450}};
  std::vector<lfd::BoundaryEvidence> evidence = {
      {20, 0.5, lfd::EvidenceKind::kClasp},         // in the first rest
      {100, 0.5, lfd::EvidenceKind::kClasp},        // in motion
      {250, 0.9, lfd::EvidenceKind::kContact},      // inside the interior pause
      {200, 0.6, lfd::EvidenceKind::kSensorLevel},  // at the pause's first sample
      {420, 0.9, lfd::EvidenceKind::kContact},      // in the last rest
  };
  lfd::gatherIntoPauses(pauses, 450, 0, &evidence);
  EXPECT_EQ(evidence[0].index, 20u) << "the first rest keeps its evidence";
  EXPECT_EQ(evidence[1].index, 100u);
  EXPECT_EQ(evidence[2].index, 300u);
  EXPECT_EQ(evidence[3].index, 200u) << "evidence as the hand stops begins the pause's phase";
  EXPECT_EQ(evidence[4].index, 420u) << "the last rest keeps its evidence";
  EXPECT_EQ(evidence[2].kind, lfd::EvidenceKind::kContact);
  EXPECT_DOUBLE_EQ(evidence[2].weight, 0.9);
}

// A press held still: the contact made within start_samples of the hand stopping stays there;
// one made later in the pause (a gripper closing while the arm waits) moves to its end.
TEST(GatherIntoPauses, EvidenceAsTheHandStopsStaysWhereItIs) {
  const std::vector<lfd::Pause> pauses = {{0, 50}, {200, 300}, {400, 450}};
  std::vector<lfd::BoundaryEvidence> evidence = {
      {208, 0.9, lfd::EvidenceKind::kContact},
      {230, 0.9, lfd::EvidenceKind::kContact},
  };
  lfd::gatherIntoPauses(pauses, 450, 10, &evidence);
  EXPECT_EQ(evidence[0].index, 208u);
  EXPECT_EQ(evidence[1].index, 300u);
}

// ---- sensoryEvidence

lfd::SensoryEvent event(std::size_t index, bool rest_edge, bool away_from_rest = true) {
  lfd::SensoryEvent e;
  e.index = index;
  e.rest_edge = rest_edge;
  e.strength = 2.0;
  e.away_from_rest = away_from_rest;
  return e;
}

// Where each level event ended up (sorted), the contacts left out.
std::vector<std::size_t> levelIndices(const std::vector<lfd::BoundaryEvidence>& evidence) {
  std::vector<std::size_t> out;
  for (const auto& e : evidence)
    if (e.kind == lfd::EvidenceKind::kSensorLevel) out.push_back(e.index);
  std::sort(out.begin(), out.end());
  return out;
}

// A press builds up after contact is made and eases off before it is lost: those join their
// edge. A force that rises before an edge of contact lost (a push ending in a snap whose drop
// reads as rest) does not, nor one that eases off long after contact is made; within the
// reversal fold (a press overshooting as it lands) it does.
// The start and the end of one ramp in contact are one change: each alone weighs less than a
// step (under min_support: the start of a torque dying out is no boundary alone), the two together
// as much as one. Folded onto a contact, the contact's weight is what counts.
TEST(SensoryEvidence, EachEndOfOneRampWeighsHalfAStepInNoisyOr) {
  lfd::SensorEvents events;
  lfd::SensoryEvent start = event(300, false, false), end = event(320, false, false);
  start.ramp_end = end.ramp_end = true;
  events.details = {start, end, event(500, false, true)};
  lfd::EvidenceWeights weights;
  weights.sensor_level = 0.75;
  const auto out = lfd::sensoryEvidence(events, weights, 25, 5);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(out[0].weight, 0.5, 1e-12);
  EXPECT_NEAR(out[1].weight, 0.5, 1e-12);
  EXPECT_NEAR(1.0 - (1.0 - out[0].weight) * (1.0 - out[1].weight), 0.75, 1e-12);
  EXPECT_DOUBLE_EQ(out[2].weight, 0.75);
}

TEST(SensoryEvidence, ALevelEventJoinsARestEdgeOnlyWhenItGoesTheEdgesWay) {
  lfd::SensorEvents events;
  events.details = {event(100, true, true),  event(115, false, true),  event(150, false, false),
                    event(200, true, true),  event(203, false, false), event(380, false, true),
                    event(400, true, false), event(480, false, false), event(500, true, false)};
  const auto out = lfd::sensoryEvidence(events, lfd::EvidenceWeights{}, 25, 5);
  // 115 builds up after 100: joins it. 150 eases off 50 after 100: beyond the fold either way.
  // 203 eases off 3 after 200: within the reversal fold. 380 rises 20 before contact lost at
  // 400: its own. 480 eases off 20 before 500: joins it.
  EXPECT_EQ(levelIndices(out), (std::vector<std::size_t>{100, 150, 200, 380, 500}));
}

TEST(SensoryEvidence, ARestEdgeIsContactWithTheContactWeight) {
  lfd::SensorEvents events;
  events.details = {event(100, true)};
  lfd::EvidenceWeights weights;
  weights.contact = 0.77;
  weights.sensor_level = 0.55;
  const auto out = lfd::sensoryEvidence(events, weights, 25, 5);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].index, 100u);
  EXPECT_EQ(out[0].kind, lfd::EvidenceKind::kContact);
  EXPECT_DOUBLE_EQ(out[0].weight, 0.77);
}

TEST(SensoryEvidence, ALevelEventNearARestEdgeJoinsItAndAFarOneStaysPut) {
  lfd::SensorEvents events;
  events.details = {event(100, true), event(120, false), event(200, false), event(300, true)};
  lfd::EvidenceWeights weights;
  weights.contact = 0.77;
  weights.sensor_level = 0.55;
  auto out = lfd::sensoryEvidence(events, weights, 25, 5);
  ASSERT_EQ(out.size(), 4u);
  std::sort(out.begin(), out.end(),
            [](const lfd::BoundaryEvidence& a, const lfd::BoundaryEvidence& b) {
              return a.index != b.index ? a.index < b.index : a.kind < b.kind;
            });
  std::size_t contacts = 0, levels = 0;
  for (const auto& e : out) {
    if (e.kind == lfd::EvidenceKind::kContact) {
      ++contacts;
      EXPECT_DOUBLE_EQ(e.weight, 0.77);
    }
    if (e.kind == lfd::EvidenceKind::kSensorLevel) ++levels;
  }
  EXPECT_EQ(contacts, 2u);
  // 120 lies 20 samples from the rest edge at 100 (fold 25): it joins it.
  EXPECT_EQ(out[0].index, 100u);
  EXPECT_EQ(out[1].index, 100u);
  // 200 lies 100 samples from either edge: a level step of its own.
  EXPECT_EQ(out[2].index, 200u);
  EXPECT_EQ(out[2].kind, lfd::EvidenceKind::kSensorLevel);
  EXPECT_DOUBLE_EQ(out[2].weight, 0.55);
  EXPECT_EQ(out[3].index, 300u);
  EXPECT_EQ(out[3].kind, lfd::EvidenceKind::kContact);
}

TEST(SensoryEvidence, ALevelEventJustBeyondTheFoldStaysPut) {
  lfd::SensorEvents events;
  events.details = {event(100, true), event(126, false)};
  const auto out = lfd::sensoryEvidence(events, lfd::EvidenceWeights{}, 25, 5);
  ASSERT_EQ(out.size(), 2u);
  for (const auto& e : out)
    if (e.kind == lfd::EvidenceKind::kSensorLevel) {
      EXPECT_EQ(e.index, 126u);
    }
}

// ---- rhythmEvidence

// A wipe's strokes start 0.4 s after the press and stop 0.3 s before the lift (50 Hz, fold 1 s):
// both edges are the contact's own and join its rest edges; a grating with no contact nearby keeps
// its edges where the strokes begin and end.
TEST(RhythmEvidence, EdgesNearAContactJoinItAndOthersStayPut) {
  const std::vector<lfd::BoundaryEvidence> contacts = {{100, 0.9, lfd::EvidenceKind::kContact},
                                                       {400, 0.9, lfd::EvidenceKind::kContact},
                                                       {120, 0.7, lfd::EvidenceKind::kSensorLevel}};
  const auto out = lfd::rhythmEvidence({{120, 385}, {600, 800}}, contacts, 0.6, 50);
  ASSERT_EQ(out.size(), 4u);
  const std::vector<std::size_t> at = {100, 400, 600, 800};
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_EQ(out[k].index, at[k]) << "edge " << k;
    EXPECT_EQ(out[k].kind, lfd::EvidenceKind::kRhythm);
    EXPECT_DOUBLE_EQ(out[k].weight, 0.6);
  }
}

}  // namespace

TEST(TypicalSpeed, IsThe95thPercentileNotTheSpike) {
  Eigen::VectorXd speed = Eigen::VectorXd::LinSpaced(101, 0.0, 1.0);  // 0, 0.01, ..., 1
  speed[50] = 100.0;                                                  // one spike
  EXPECT_NEAR(lfd::typicalSpeed(speed), 0.96, 1e-12);  // the 95th of the 101 values, spike last
  EXPECT_EQ(lfd::typicalSpeed(Eigen::VectorXd()), 0.0);
}
