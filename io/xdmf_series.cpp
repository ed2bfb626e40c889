#include "io/xdmf_series.hpp"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"
#include "io/vtk_output.hpp"  // write_file_atomically

namespace fdem {

namespace {

const char* data_type(FrameValue type) {
  return type == FrameValue::f64 ? "Float" : "Int";
}
int precision(FrameValue type) {
  return type == FrameValue::i32 ? 4 : 8;
}  // bytes per value

// XDMF names the shape of an attribute by its components per row.
const char* attribute_type(int components) {
  switch (components) {
    case 1:
      return "Scalar";
    case 3:
      return "Vector";
    case 9:
      return "Tensor";
    default:
      return "Matrix";
  }
}

void data_item(std::ostringstream& xml, const std::string& indent, const FrameFileInfo& frame,
               const FrameDataset& d) {
  xml << indent << "<DataItem DataType=\"" << data_type(d.type) << "\" Precision=\""
      << precision(d.type) << "\" Dimensions=\"" << d.rows;
  if (d.components > 1) xml << ' ' << d.components;
  xml << "\" Format=\"HDF\">" << frame.file << ':' << d.path << "</DataItem>\n";
}

}  // namespace

std::string xdmf_series_xml(const std::string& series, const std::vector<FrameFileInfo>& frames) {
  std::ostringstream xml;
  xml << std::setprecision(17);
  xml << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      << "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
      << "  <Domain>\n"
      << "    <Grid Name=\"" << series
      << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const FrameFileInfo& frame = frames[f];
    xml << "      <Grid Name=\"" << series << '_' << std::setw(6) << std::setfill('0') << f
        << std::setfill(' ') << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << frame.time << "\"/>\n";
    const std::string item = "          ";
    for (const FrameDataset& d : frame.datasets)
      if (d.role == FrameDataset::Role::topology) {
        xml << "        <Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"" << d.rows
            << "\" NodesPerElement=\"4\">\n";
        data_item(xml, item, frame, d);
        xml << "        </Topology>\n";
      }
    for (const FrameDataset& d : frame.datasets)
      if (d.role == FrameDataset::Role::geometry) {
        xml << "        <Geometry GeometryType=\"XYZ\">\n";
        data_item(xml, item, frame, d);
        xml << "        </Geometry>\n";
      }
    for (const FrameDataset& d : frame.datasets) {
      if (d.role != FrameDataset::Role::point && d.role != FrameDataset::Role::cell) continue;
      xml << "        <Attribute Name=\"" << d.name << "\" AttributeType=\""
          << attribute_type(d.components) << "\" Center=\""
          << (d.role == FrameDataset::Role::cell ? "Cell" : "Node") << "\">\n";
      data_item(xml, item, frame, d);
      xml << "        </Attribute>\n";
    }
    xml << "      </Grid>\n";
  }
  xml << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return xml.str();
}

XdmfSeries::XdmfSeries(std::string directory, std::string series, bool writer)
    : directory_(std::move(directory)), series_(std::move(series)), writer_(writer) {
  if (writer_) std::filesystem::create_directories(std::filesystem::path(directory_) / series_);
}

std::string XdmfSeries::next_frame_file() const {
  std::ostringstream name;
  name << series_ << "/" << series_ << "_" << std::setw(6) << std::setfill('0') << frames_.size()
       << ".h5";
  return name.str();
}

std::string XdmfSeries::path() const {
  return (std::filesystem::path(directory_) / (series_ + ".xdmf")).string();
}

void XdmfSeries::add_frame(FrameFileInfo frame) {
  frames_.push_back(std::move(frame));
  if (writer_) write_file_atomically(path(), xdmf_series_xml(series_, frames_));
}

}  // namespace fdem
