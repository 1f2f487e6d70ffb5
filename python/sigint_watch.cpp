#include "sigint_watch.h"

namespace buckle::python {

namespace py = pybind11;

namespace {

std::atomic<bool> gInterrupted{false};

void onSigint(int) { gInterrupted.store(true); }

}  // namespace

SigintWatch::SigintWatch() {
  py::module_ threading = py::module_::import("threading");
  if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return;
  py::module_ signal = py::module_::import("signal");
  if (!signal.attr("getsignal")(signal.attr("SIGINT")).is(signal.attr("default_int_handler"))) return;
  gInterrupted.store(false);
  struct sigaction action {};
  action.sa_handler = onSigint;
  sigemptyset(&action.sa_mask);
  installed_ = ::sigaction(SIGINT, &action, &previous_) == 0;
}

SigintWatch::~SigintWatch() {
  if (installed_) ::sigaction(SIGINT, &previous_, nullptr);
}

const std::atomic<bool>* SigintWatch::flag() const { return installed_ ? &gInterrupted : &never_; }

bool SigintWatch::interrupted() const { return installed_ && gInterrupted.load(); }

void SigintWatch::raiseIfInterrupted() const {
  if (!interrupted()) return;
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw py::error_already_set();
}

}  // namespace buckle::python
