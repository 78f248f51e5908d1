#pragma once

#include <filesystem>
#include <string_view>

namespace icewatch::daemon {

// Replaces path with content so that a reader, a crash or a power cut at any moment finds either
// the old or the new file, never a mix: a temporary file in the same directory, written and
// fsync'ed, renamed over path, then the directory fsync'ed so the rename itself is durable.
// Returns false (errno kept, nothing at path changed) on failure; the caller logs.
// Durability::AtomicOnly skips the fsyncs: still never a mix, but a power cut may leave the old
// content (for pictures meant for a person, not worth two flash writes per cycle).
enum class Durability { Durable, AtomicOnly };
bool writeFileAtomically(const std::filesystem::path& path, std::string_view content,
                         Durability durability = Durability::Durable);

// Removes temporary files an interrupted writeFileAtomically left in dir.
void removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace icewatch::daemon
