// InputError: what render/ throws when a request's content cannot be rendered (a bad mesh, a
// parameter out of range, a limit exceeded). The api layer maps each Kind to an HTTP status;
// render/ itself knows nothing of HTTP.
#pragma once

#include <stdexcept>
#include <string>

namespace limn::render {

class InputError : public std::runtime_error {
 public:
  enum class Kind {
    InvalidMesh,       // the mesh is malformed or the scheme cannot take it (422)
    InvalidParameter,  // a parameter is out of its range (400)
    LimitExceeded,     // a configured resource limit would be exceeded (413)
    EmptySurface,      // the input is valid but describes no surface at all (422)
  };

  // `subject` names the culprit: a limit key ("maxFaces"), a parameter ("params.level"),
  // or an element of the mesh ("face 12", "crease 3").
  InputError(Kind kind, std::string subject, const std::string& message)
      : std::runtime_error(message), kind_(kind), subject_(std::move(subject)) {}

  Kind kind() const { return kind_; }
  const std::string& subject() const { return subject_; }

 private:
  Kind kind_;
  std::string subject_;
};

// Thrown when a job's deadline passed or the job was cancelled (server shutdown).
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace limn::render
