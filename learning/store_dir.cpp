#include "learning/detail/store_dir.hpp"

#include <unistd.h>

#include <cstdlib>
#include <system_error>

#include "learning/detail/memory_state.hpp"

namespace orthoflow::learning {

namespace fs = std::filesystem;

StoreDir inspect_store_dir(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (ec || status.type() == fs::file_type::not_found) {
    return ec && ec != std::errc::no_such_file_or_directory ? StoreDir::FOREIGN : StoreDir::ABSENT;
  }
  if (!fs::is_directory(status)) return StoreDir::FOREIGN;
  bool any = false, leveldb_files = false, current = false;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    any = true;
    const std::string name = entry.path().filename().string();
    current = current || name == "CURRENT";
    leveldb_files = leveldb_files || name.rfind("MANIFEST-", 0) == 0 ||
                    entry.path().extension() == ".ldb" || entry.path().extension() == ".log" ||
                    name == "LOCK" || name == "LOG";
  }
  if (ec) return StoreDir::FOREIGN;
  if (!any) return StoreDir::EMPTY;
  if (current) return StoreDir::STORE;
  return leveldb_files ? StoreDir::DAMAGED : StoreDir::FOREIGN;
}

bool writable_dir(const fs::path& dir) noexcept { return ::access(dir.c_str(), W_OK) == 0; }

Result<fs::path, MemoryError> private_copy(const fs::path& dir) {
  std::string pattern = (fs::temp_directory_path() / "orthoflow-store-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    return err(memory_error(MemoryError::Code::OPEN_FAILED, dir,
                            "cannot make a private copy of a read-only store"));
  }
  const fs::path copy(pattern);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file() || entry.path().filename() == "LOCK") continue;
    fs::copy_file(entry.path(), copy / entry.path().filename(), ec);
    if (ec) break;
  }
  if (ec) {
    fs::remove_all(copy, ec);
    return err(memory_error(MemoryError::Code::OPEN_FAILED, dir,
                            "cannot read the read-only store: " + ec.message()));
  }
  return copy;
}

bool inside_store(const fs::path& file, const fs::path& dir) {
  std::error_code ec;
  const fs::path store = fs::weakly_canonical(dir, ec);
  const fs::path target = fs::weakly_canonical(file, ec);
  const auto [s, t] = std::mismatch(store.begin(), store.end(), target.begin(), target.end());
  return s == store.end();
}

}  // namespace orthoflow::learning
