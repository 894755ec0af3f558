// SPDX-License-Identifier: BSD-3-Clause
// C API: building, freeing and reading the opaque model. The only calls of the C API that
// allocate; every exception stops here and becomes a NULL model and a one-line message.
#include <cstring>
#include <new>

#include "c_api.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/io/text_file.hpp"

namespace {

using namespace hexatwist;
using hexatwist::c_api::write_error;

// Runs `make` (which returns a Model) and wraps the result, or writes why it failed.
template <class Make>
hexatwist_model* build(Make&& make, char* error, std::size_t error_size) noexcept {
  try {
    Model model = make();
    std::string name = model.spec().name;
    return new hexatwist_model{std::move(model), std::move(name)};
  } catch (const std::bad_alloc&) {
    write_error("out of memory", error, error_size);
  } catch (const std::exception& e) {
    write_error(e.what(), error, error_size);
  } catch (...) {
    write_error("unknown error", error, error_size);
  }
  return nullptr;
}

}  // namespace

extern "C" {

hexatwist_model* hexatwist_model_from_file(const char* path, char* error, size_t error_size) {
  if (path == nullptr) {
    write_error("configuration file: no path given (NULL)", error, error_size);
    return nullptr;
  }
  return build([&] { return load_model(read_text_file(path, "configuration file", kMaxConfigBytes), path); }, error,
               error_size);
}

hexatwist_model* hexatwist_model_from_yaml(const char* yaml_text, const char* source, char* error, size_t error_size) {
  if (yaml_text == nullptr) {
    write_error("configuration text: none given (NULL)", error, error_size);
    return nullptr;
  }
  return build([&] { return load_model(yaml_text, source != nullptr ? source : "<yaml text>"); }, error, error_size);
}

hexatwist_model* hexatwist_model_default(char* error, size_t error_size) {
  return build([] { return default_model(); }, error, error_size);
}

void hexatwist_model_free(hexatwist_model* model) { delete model; }

const char* hexatwist_model_name(const hexatwist_model* model) { return model != nullptr ? model->name.c_str() : ""; }

double hexatwist_model_home_height(const hexatwist_model* model) {
  return model != nullptr ? model->model.spec().home_height : 0.0;
}

void hexatwist_model_home_lengths(const hexatwist_model* model, double geometric[HEXATWIST_LEGS],
                                  double motor[HEXATWIST_LEGS]) {
  if (model == nullptr) return;
  const Model& m = model->model;
  // At home the twist is zero by definition: motor-side = geometric - offset, through the drives'
  // reference and scale (theory §4).
  if (geometric != nullptr) c_api::from_vector(m.length_home(), geometric);
  if (motor != nullptr) c_api::from_vector(m.motor_from_travel(m.length_home() - m.geometry().length_offset), motor);
}

void hexatwist_model_home_commands(const hexatwist_model* model, double motor[HEXATWIST_LEGS]) {
  if (model == nullptr || motor == nullptr) return;
  c_api::from_vector(model->model.home_command(), motor);
}

int hexatwist_model_play(const hexatwist_model* model, double play[HEXATWIST_LEGS]) {
  if (model == nullptr) return 0;
  if (play != nullptr) c_api::from_vector(2.0 * model->model.geometry().half_play, play);
  return model->model.has_play() ? 1 : 0;
}

hexatwist_model* hexatwist_model_without_play(const hexatwist_model* model, char* error, size_t error_size) {
  if (model == nullptr) {
    write_error("model: none given (NULL)", error, error_size);
    return nullptr;
  }
  return build(
      [&] {
        ModelSpec spec = model->model.spec();
        for (LegSpec& leg : spec.legs) leg.play = 0.0;
        return Model(spec);
      },
      error, error_size);
}

int hexatwist_model_expands(const hexatwist_model* model, double* reference_temperature) {
  if (model == nullptr) return 0;
  if (reference_temperature != nullptr) *reference_temperature = model->model.reference_temperature();
  return model->model.has_thermal() ? 1 : 0;
}

void hexatwist_model_stroke(const hexatwist_model* model, double* length_min, double* length_max) {
  if (model == nullptr) return;
  if (length_min != nullptr) *length_min = model->model.spec().limits.length_min;
  if (length_max != nullptr) *length_max = model->model.spec().limits.length_max;
}

}  // extern "C"
