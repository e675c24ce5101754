#pragma once
// XML files of other tools (MPCDI descriptions, SGCT clusters, SimCAD warps), parsed by pugixml.
#include <pugixml.hpp>
#include <string>
#include <string_view>

#include "facet/projection/errors.hpp"

namespace facet::interop {

// Parses `xml` into `document`; InputError naming `source` and the byte where it stops being
// well-formed otherwise.
inline void load_xml(pugi::xml_document& document, std::string_view xml,
                     const std::string& source) {
  const pugi::xml_parse_result parsed = document.load_buffer(xml.data(), xml.size());
  if (!parsed) {
    throw InputError(source, "",
                     std::string("expected well-formed XML: ") + parsed.description() +
                         " at byte " + std::to_string(parsed.offset));
  }
}

}  // namespace facet::interop
