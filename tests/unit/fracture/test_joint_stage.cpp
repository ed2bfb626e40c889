// The joint stage's state as it travels between ranks: each joint's history as an opaque record,
// back bit for bit.
#include <catch2/catch.hpp>
#include <cstring>

#include "fracture/joint_stage.hpp"

using namespace fdem;

TEST_CASE("joint histories travel as opaque records and come back bit for bit",
          "[fracture][state]") {
  std::vector<JointHistory> history(4);
  history[1].broken = true;
  history[1].mode = FailureMode::shear;
  history[1].failure_time = 0.125;
  history[2].point[0].damage = 0.3;
  history[3].point[2].damage = 1.0 / 3.0;
  const std::vector<std::uint8_t> records = joint_records(history);
  CHECK(records.size() == 4 * sizeof(JointHistory));
  const std::vector<JointHistory> back = joint_histories(records);
  REQUIRE(back.size() == 4);
  CHECK(std::memcmp(back.data(), history.data(), records.size()) == 0);
  CHECK(back[1].broken);
  CHECK(back[1].mode == FailureMode::shear);
  CHECK(back[1].failure_time == 0.125);
  CHECK(back[3].point[2].damage == 1.0 / 3.0);
  CHECK(joint_histories({}).empty());
  CHECK_THROWS(joint_histories(std::vector<std::uint8_t>(sizeof(JointHistory) + 1)));
}
