// Writes a damaged copy of a model file for the failure tests (tests/mpi/damaged_model_file.cmake):
//   damage_model_file GOOD.h5 BAD.h5 MODE
// MODE (each in the last tet, which the last rank's slice holds; checksums and seal rewritten, so
// that the reader's own checks find the damage):
//   node-row  the last tet's second node is a row beyond the node table
//   nan       a coordinate of a node of the last tet is NaN
//   invert    the last tet's last two nodes swapped (negative volume)
// and (file changed behind the checksums):
//   flip      one node index of /tets/nodes changed in place (the dataset checksum is stale)
//   truncate  the file cut 1000 bytes short
#include <hdf5.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include "parallel/model_file.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: damage_model_file GOOD.h5 BAD.h5 MODE\n");
    return 2;
  }
  const std::string good = argv[1], bad = argv[2], mode = argv[3];
  namespace fs = std::filesystem;
  try {
    if (mode == "flip" || mode == "truncate") {
      fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
      if (mode == "truncate") {
        fs::resize_file(bad, fs::file_size(bad) - 1000);
        return 0;
      }
      const hid_t file = H5Fopen(bad.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      const hid_t dataset = H5Dopen2(file, "/tets/nodes", H5P_DEFAULT);
      const hid_t space = H5Dget_space(dataset);
      hsize_t dims[2] = {0, 0};
      H5Sget_simple_extent_dims(space, dims, nullptr);
      const std::array<hsize_t, 2> start{dims[0] - 1, 0}, count{1, 1};
      H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
      const hsize_t one = 1;
      const hid_t memory = H5Screate_simple(1, &one, nullptr);
      const std::int64_t other = 0;
      const herr_t status = H5Dwrite(dataset, H5T_NATIVE_INT64, memory, space, H5P_DEFAULT, &other);
      H5Sclose(memory);
      H5Sclose(space);
      H5Dclose(dataset);
      H5Fclose(file);
      return status < 0 ? 1 : 0;
    }
    fdem::ModelFileContent c = fdem::read_model_file_content(good);
    const std::size_t last = c.tet_tag.size() - 1;
    if (mode == "node-row")
      c.tet_nodes[4 * last + 1] = c.header.n_nodes + 7;
    else if (mode == "nan")
      c.node_x[3 * static_cast<std::size_t>(c.tet_nodes[4 * last + 3]) + 1] =
          std::numeric_limits<double>::quiet_NaN();
    else if (mode == "invert")
      std::swap(c.tet_nodes[4 * last + 2], c.tet_nodes[4 * last + 3]);
    else {
      std::fprintf(stderr, "damage_model_file: unknown mode '%s'\n", mode.c_str());
      return 2;
    }
    fdem::write_model_file(c, bad);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "damage_model_file: %s\n", e.what());
    return 1;
  }
  return 0;
}
