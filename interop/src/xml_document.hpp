#pragma once
// XML files of other tools (MPCDI descriptions, SGCT clusters, SimCAD warps), parsed by pugixml.
#include <cmath>
#include <cstdlib>
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

// A finite number written as `text` (surrounding white space allowed); InputError naming
// `source` and `field` otherwise.
inline double parse_number(const std::string& text, const std::string& source,
                           const std::string& field) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  const char* begin = text.c_str();
  while (space(*begin)) ++begin;
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  while (end && space(*end)) ++end;
  if (end == begin || !end || *end != '\0' || !std::isfinite(value)) {
    throw InputError(source, field,
                     "expected a finite number, found \"" + text.substr(0, 40) + "\"");
  }
  return value;
}

}  // namespace facet::interop
