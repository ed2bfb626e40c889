// Friction entries as the pair records that travel with their first tet, and back
// (contact_stage.hpp).
#include <algorithm>

#include "contact/contact_stage.hpp"

namespace fdem {

std::vector<PairRecord> friction_records(const std::vector<FrictionEntry>& entries) {
  std::vector<PairRecord> records(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const FrictionEntry& e = entries[i];
    PairRecord& r = records[i];
    r.a = e.a;
    r.b = e.b;
    r.value[0] = e.spring.x();
    r.value[1] = e.spring.y();
    r.value[2] = e.spring.z();
    r.value[3] = e.stiffness;
    std::copy_n(e.anchor_a, 4, r.value + 4);
    std::copy_n(e.anchor_b, 4, r.value + 8);
  }
  return records;
}

std::vector<FrictionEntry> friction_entries(const std::vector<PairRecord>& records) {
  std::vector<FrictionEntry> entries(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const PairRecord& r = records[i];
    entries[i].a = r.a;
    entries[i].b = r.b;
    entries[i].spring = Vec3(r.value[0], r.value[1], r.value[2]);
    entries[i].stiffness = r.value[3];
    std::copy_n(r.value + 4, 4, entries[i].anchor_a);
    std::copy_n(r.value + 8, 4, entries[i].anchor_b);
  }
  return entries;
}

}  // namespace fdem
