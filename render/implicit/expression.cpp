#include "render/implicit/expression.h"

#include <muParser.h>

#include <cmath>

#include "render/core/error.h"

namespace limn::render::implicit {

ExpressionSet::ExpressionSet(std::vector<std::string> sources, std::vector<std::string> subjects)
    : sources_(std::move(sources)), subjects_(std::move(subjects)) {
  compile();
}

ExpressionSet::~ExpressionSet() = default;

void ExpressionSet::compile() {
  parsers_.clear();
  for (size_t i = 0; i < sources_.size(); ++i) {
    auto parser = std::make_unique<mu::Parser>();
    try {
      // Only the three coordinates are known names: anything else fails to compile.
      parser->DefineVar("x", &x_);
      parser->DefineVar("y", &y_);
      parser->DefineVar("z", &z_);
      parser->SetExpr(sources_[i]);
      x_ = y_ = z_ = 0.25;
      parser->Eval();  // compiles to bytecode and catches what SetExpr lets through
    } catch (const mu::Parser::exception_type& e) {
      throw InputError(InputError::Kind::InvalidParameter, subjects_[i],
                       "expression does not compile (" + e.GetMsg() +
                           "); it may use x, y, z, numbers, operators and muparser's functions "
                           "(sin, cos, sqrt, exp, abs, min, max, ...)");
    }
    parsers_.push_back(std::move(parser));
  }
}

std::unique_ptr<ExpressionSet> ExpressionSet::clone() const {
  return std::make_unique<ExpressionSet>(sources_, subjects_);
}

double ExpressionSet::evaluate(int index, double x, double y, double z) {
  x_ = x;
  y_ = y;
  z_ = z;
  double value;
  try {
    value = parsers_[index]->Eval();
  } catch (const mu::Parser::exception_type&) {
    return 0.0;  // e.g. a division by zero muparser reports: no contribution there
  }
  return std::isfinite(value) ? value : 0.0;
}

}  // namespace limn::render::implicit
