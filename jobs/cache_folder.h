// Where baked models are cached when nobody names a folder: one rule for the service, the
// C API and the lod command, so that an installed program never writes into a build tree.
#pragma once
#include <filesystem>

namespace lod {

// The first of: `asked` (a command's --cache, or a caller's explicit folder), `configured`
// (a config's [cache] dir), $LOD_CACHE_DIR, $XDG_CACHE_HOME/lodkit (when absolute, as the
// XDG base directory spec requires), $HOME/.cache/lodkit, <temp directory>/lodkit-cache.
// Empty arguments and empty variables count as absent. The folder is not created here.
std::filesystem::path cache_dir_for(const std::filesystem::path& asked, const std::filesystem::path& configured);

}  // namespace lod
