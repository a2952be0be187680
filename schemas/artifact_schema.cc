#include "schemas/artifact_schema.h"

#include <fmt/format.h>

#include "schemas/errors.h"
#include "schemas/h5_access.h"
#include "schemas/json_fields.h"

namespace speckle {

int RequireSchemaVersion(const std::string& where, const std::string& schema, long long found, int version,
                         int oldest) {
  if (oldest < 0) oldest = version;
  if (found < oldest || found > version) {
    throw SchemaVersionError(where + ": " + schema + " schema version " + std::to_string(found) +
                             " is not understood (this tool reads version " +
                             (oldest == version ? std::to_string(version) : fmt::format("{} to {}", oldest, version)) +
                             ")");
  }
  return static_cast<int>(found);
}

nlohmann::json ReadArtifactJson(const std::filesystem::path& path, const std::string& schema, int version,
                                int oldest_version) {
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": missing");
  const nlohmann::json j = ReadJsonFile(path.string());
  if (!j.is_object() || j.value("schema", "") != schema)
    throw InputError(path.string() + ": not a " + schema + " file (key \"schema\")");
  RequireSchemaVersion(path.string(), schema, j.value("schema_version", -1), version, oldest_version);
  return j;
}

int CheckSchema(const H5::H5File& file, const std::string& where, const std::string& name, int version, int oldest) {
  const std::string schema = h5::ReadStringAttribute(file, "schema", where);
  if (schema != name) throw InputError(where + ": attribute 'schema' is \"" + schema + "\", expected \"" + name + "\"");
  return RequireSchemaVersion(where, name, h5::ReadIntAttribute(file, "schema_version", where), version, oldest);
}

}  // namespace speckle
