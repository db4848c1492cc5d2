#include "python/options.h"

#include <cstdlib>
#include <filesystem>

#include "cli/apply_flags.h"
#include "cli/flag_values.h"
#include "cli/usage.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

// A number, or a word, as the command line would type it.
std::string scalar_text(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value))
    throw py::value_error(key + "= takes no True or False inside a list (got " + py::repr(value).cast<std::string>() + ")");
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)) return py::repr(value).cast<std::string>();
  // numpy scalars and other numbers: as their float or int
  if (py::hasattr(value, "__index__")) return py::repr(py::int_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  if (py::hasattr(value, "__float__")) return py::repr(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  throw py::value_error(key + "= must be a number or a string (got " + py::repr(value).cast<std::string>() + ")");
}

}  // namespace

std::vector<std::string> option_args(const py::dict& options, std::string* volumes_text) {
  std::vector<std::string> args;
  for (const auto& item : options) {
    const std::string key = py::str(item.first);
    const py::handle value = item.second;
    std::string flag = "--" + key;
    for (char& c : flag)
      if (c == '_') c = '-';
    if (value.is_none() || (py::isinstance<py::bool_>(value) && !value.cast<bool>())) continue;
    if (py::isinstance<py::bool_>(value)) {
      args.push_back(flag);
      continue;
    }
    if (key == "volumes" && (py::isinstance<py::dict>(value) || py::isinstance<py::list>(value))) {
      *volumes_text = py::module_::import("json").attr("dumps")(value).cast<std::string>();
      args.push_back(flag);
      args.push_back("volumes= (a document)");
      continue;
    }
    if (py::isinstance<py::tuple>(value) || py::isinstance<py::list>(value) ||
        (py::hasattr(value, "ndim") && py::hasattr(value, "tolist") && value.attr("ndim").cast<int>() > 0)) {
      const py::sequence seq = py::hasattr(value, "tolist") && !py::isinstance<py::sequence>(value)
                                   ? py::sequence(value.attr("tolist")())
                                   : py::reinterpret_borrow<py::sequence>(value);
      std::string text;
      for (std::size_t i = 0; i < seq.size(); ++i) text += (i == 0 ? "" : ",") + scalar_text(key, seq[i]);
      args.push_back(flag);
      args.push_back(text);
      continue;
    }
    if (py::hasattr(value, "__fspath__")) {  // pathlib.Path
      args.push_back(flag);
      args.push_back(py::module_::import("os").attr("fspath")(value).cast<std::string>());
      continue;
    }
    args.push_back(flag);
    args.push_back(scalar_text(key, value));
  }
  return args;
}

cli::ApplyOptions apply_options(const py::dict& options) {
  std::string volumes_text;
  const std::vector<std::string> args = option_args(options, &volumes_text);
  try {
    // FOGCL_DEVICE is device='s default, under the same rule (as for the command line).
    const char* env_device = std::getenv("FOGCL_DEVICE");
    if (env_device != nullptr && *env_device != '\0' && !options.contains("device"))
      cli::check_device("FOGCL_DEVICE", env_device);
    cli::ApplyOptions o = cli::parse_memory_apply_args(args);
    o.volumes.volumes_text = volumes_text;
    return o;
  } catch (const Error& e) {  // UsageError too: both are the caller's options
    throw py::value_error(e.what());
  }
}

std::string options_key(const py::dict& options, const cli::ApplyOptions& o) {
  std::string volumes_text, key;
  for (const std::string& a : option_args(options, &volumes_text)) key += a + '\0';
  key += volumes_text;
  for (const std::string& file : {o.volumes.volumes_path, o.volumes.shadow_map_path}) {
    if (file.empty() || (file == o.volumes.volumes_path && !o.volumes.volumes_text.empty())) continue;
    std::error_code size_error, time_error;
    const auto size = std::filesystem::file_size(file, size_error);
    const auto time = std::filesystem::last_write_time(file, time_error);
    key += '\0' + file + (size_error || time_error ? std::string(" (unreadable)")
                                                    : " " + std::to_string(size) + " " +
                                                          std::to_string(time.time_since_epoch().count()));
  }
  return key;
}

}  // namespace fogcl::python
