#pragma once
// Writing output files so that a failure never leaves a partial file behind.
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string_view>

#include "facet/projection/errors.hpp"

namespace facet {

// Calls write(temporary_path) with a path in the same folder as `path`, then renames it onto
// `path`. If write throws, the temporary file is removed and the exception propagates. A `path`
// that exists and is not a regular file (a folder, a device such as /dev/null, a FIFO, a socket,
// a symbolic link) is an InputError before anything is written: the rename would replace it.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write);

// The checks an output file passes before a command starts its work, so that a path it could
// never write is refused at once rather than after the work: InputError naming `path` and `field`
// when `path` is empty or names a folder (".", "..", a trailing '/'), exists and is not a regular
// file (write_atomically's check), has a file name longer than 255 bytes, or its folder is not an
// existing folder that takes a new file (one is made and removed at once to find out).
void check_output_file(const std::filesystem::path& path, const InputField& field);

// InputError naming `out` and `field` when `out` is the same file as one of `inputs` (after links
// and relative paths): writing it would replace an input the command reads.
void refuse_output_over_inputs(const std::filesystem::path& out, const InputField& field,
                               std::initializer_list<std::filesystem::path> inputs);

}  // namespace facet
