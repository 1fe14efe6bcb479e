// The engine's variable table behaves as a map from key to variable under
// random inserts and erases: states added in order (a run), removed from
// the front (a fixed lag), far apart (a user's graph that skips steps), the
// constants; through copies (a smoother snapshots its engine).
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "solvers/var_table.h"

using gssm::Key;
using gssm::internal::EngineVar;
using gssm::internal::VarTable;

namespace {
// The table's content as (key → anchor[0], δ[0], clique, slots) in key order.
using Content = std::map<Key, std::vector<double>>;
std::vector<double> summary(const EngineVar& v) {
  std::vector<double> s{v.anchor()[0], v.delta()[0], static_cast<double>(v.clique), static_cast<double>(v.dim())};
  for (int slot : v.slots) s.push_back(slot);
  return s;
}
Content contentOf(const VarTable& t) {
  Content c;
  t.forEach([&](const Key& k, const EngineVar& v) { EXPECT_TRUE(c.emplace(k, summary(v)).second) << k.toString(); });
  return c;
}
void expectSame(const VarTable& t, const Content& ref, int step) {
  ASSERT_EQ(t.size(), ref.size()) << "step " << step;
  EXPECT_EQ(contentOf(t), ref) << "step " << step;
  for (const auto& kv : ref) {
    ASSERT_NE(t.find(kv.first), nullptr) << kv.first.toString() << " step " << step;
    EXPECT_EQ(summary(t.at(kv.first)), kv.second);
  }
}
}  // namespace

TEST(VarTable, MatchesAMapThroughRandomInsertsErasesAndCopies) {
  std::mt19937 rng(3);
  VarTable table;
  Content ref;
  std::int64_t next = 0, oldest = 0;
  for (int step = 0; step < 20000; ++step) {
    Key k;
    const unsigned op = rng() % 10;
    if (op < 4) k = Key::state(next++);                            // the next step
    else if (op == 4) k = Key::state(oldest++);                    // the oldest (erased below if present)
    else if (op == 5) k = Key::constants();
    else if (op == 6) k = Key::state(static_cast<std::int64_t>(rng() % 4000000) - 2000000);  // far away
    else k = Key::state(next - 1 - static_cast<std::int64_t>(rng() % 50));  // near the end
    const bool erase = op == 4 || (op >= 6 && rng() % 2 == 0) || (op == 5 && ref.count(k));
    if (erase) {
      table.erase(k);
      ref.erase(k);
    } else if (!ref.count(k)) {
      const Eigen::Index dim = 1 + static_cast<Eigen::Index>(rng() % 3);
      EngineVar v(Eigen::VectorXd::Constant(dim, static_cast<double>(step)));
      v.delta()[0] = -step;
      v.clique = step % 97;
      for (unsigned i = 0; i < rng() % 7; ++i) v.slots.push_back(static_cast<int>(rng() % 100));
      ref[k] = summary(v);
      table.insert(k, std::move(v));
    } else {
      EXPECT_THROW(table.insert(k, EngineVar(Eigen::VectorXd::Zero(1))), std::logic_error);
    }
    EXPECT_EQ(table.contains(k), ref.count(k) == 1);
    if (step % 997 == 0) {
      expectSame(table, ref, step);
      const VarTable copy = table;  // deep: changing the copy leaves the table
      expectSame(copy, ref, step);
      VarTable other = copy;
      other.forEach([](const Key&, EngineVar& v) { v.delta().setConstant(1e9); });
      expectSame(table, ref, step);
    }
  }
  expectSame(table, ref, 20000);
  EXPECT_THROW(table.at(Key::state(next + 5000000)), std::out_of_range);
  EXPECT_THROW(table.insert(Key::state(next + 7), EngineVar()), std::logic_error);  // empty value
}

TEST(VarTable, ARunThatMovesForwardKeepsOnlyItsWindow) {
  // A fixed lag: add step k, erase step k − 10. All lookups by index, none far.
  VarTable table;
  for (std::int64_t k = 0; k < 100000; ++k) {
    table.insert(Key::state(k), EngineVar(Eigen::VectorXd::Constant(2, static_cast<double>(k))));
    if (k >= 10) table.erase(Key::state(k - 10));
  }
  EXPECT_EQ(table.size(), 10u);
  for (std::int64_t k = 99990; k < 100000; ++k) EXPECT_EQ(table.at(Key::state(k)).anchor()[1], k);
  EXPECT_FALSE(table.contains(Key::state(99989)));
}
