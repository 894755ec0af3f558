// SPDX-License-Identifier: BSD-3-Clause
// hexatwist.Stream: the real-time command stream for one pose at a time (stream.hpp), with its
// reject policy and rate limits.
#include <memory>

#include "common.hpp"

namespace hexatwist::python {
namespace {

struct PyStream {
  std::shared_ptr<Model> model;
  StreamSettings settings;
  std::unique_ptr<StreamState> state = std::make_unique<StreamState>();
};

Pose pose_of(const py::object& obj) {
  const Rows6 r = rows6(obj, "pose");
  if (!r.single) raise_input("pose: expected 6 numbers x, y, z [m], roll, pitch, yaw [rad]");
  return pose_row(r.data, 0);
}

}  // namespace

void expose_stream(py::module_& m) {
  py::class_<PyStream>(m, "Stream",
                       "The real-time command stream (stream.hpp): one pose in, one checked set of six motor-side "
                       "commands out; a rejected pose is answered with its status and the held command (or none).")
      .def(py::init([](std::shared_ptr<Model> model, const std::string& strategy, const std::string& on_reject,
                       double period, double max_velocity, double max_acceleration) {
             auto s = std::make_unique<PyStream>();
             s->model = std::move(model);
             s->settings.strategy = strategy_from(strategy);
             if (on_reject == "hold")
               s->settings.on_reject = RejectPolicy::Hold;
             else if (on_reject == "skip")
               s->settings.on_reject = RejectPolicy::Skip;
             else
               raise_input("on_reject: expected 'hold' or 'skip', got '" + on_reject + "'");
             s->settings.period = period;
             s->settings.max_velocity = max_velocity;
             s->settings.max_acceleration = max_acceleration;
             if (auto why = check_stream_settings(*s->model, s->settings); !why.empty()) raise_input(std::string(why));
             return s;
           }),
           py::arg("model"), py::arg("strategy") = "compensated", py::arg("on_reject") = "hold",
           py::arg("period") = 1e-3, py::arg("max_velocity") = std::numeric_limits<double>::infinity(),
           py::arg("max_acceleration") = std::numeric_limits<double>::infinity(),
           "period [s], max_velocity [m/s], max_acceleration [m/s^2] per leg command.")
      .def(
          "start",
          [](PyStream& s, const py::object& pose) {
            const Status st = start_stream(*s.model, s.settings, pose_of(pose), *s.state);
            if (st != Status::Ok) raise_status(st, "start pose");
          },
          py::arg("pose"), "Starts the stream at a pose the platform stands at [m, rad] (e.g. home).")
      .def(
          "_pose",
          [](PyStream& s, const py::object& pose) {
            StreamOutput out;
            const Status st = stream_pose(*s.model, s.settings, pose_of(pose), *s.state, out);
            py::dict d;
            d["input"] = out.input;
            d["status"] = std::string(to_string(st));
            d["action"] = std::string(to_string(out.action));
            d["rate_limited"] = out.rate_limited;
            d["command"] = out.action == CommandAction::None ? py::object(py::none())
                                                             : py::object(py::array_t<double>(6, out.command.data()));
            d["leg"] = leg_number(out.limit.leg);
            d["value"] = out.limit.value;
            d["bound"] = out.limit.bound;
            return d;
          },
          py::arg("pose"),
          "One input pose [x, y, z m, roll, pitch, yaw rad] (hexatwist.Stream.pose types the result): dict with "
          "input, status, action "
          "('new'|'held'|'none'), rate_limited, command (6,) [m] or None, and leg/value/bound of a limit.");
}

}  // namespace hexatwist::python
