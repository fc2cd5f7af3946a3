// Custom field primitives: expressions in x, y, z compiled by muparser. muparser has no loops,
// recursion, strings or I/O, so an expression can only compute with its three variables and
// muparser's built-in functions and constants; its cost per evaluation is linear in its length,
// which the api layer bounds (limits.maxExpressionLength). Each evaluating thread needs its own
// compiled copy (a parser reads its variables through pointers): clone() makes one.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace mu {
class Parser;
}

namespace limn::render::implicit {

class ExpressionSet {
 public:
  // Compiles every source; throws InputError naming "<subjects[i]>" when one does not compile,
  // uses a name other than x, y and z, or cannot be evaluated.
  ExpressionSet(std::vector<std::string> sources, std::vector<std::string> subjects);
  ~ExpressionSet();
  ExpressionSet(const ExpressionSet&) = delete;
  ExpressionSet& operator=(const ExpressionSet&) = delete;

  std::unique_ptr<ExpressionSet> clone() const;
  // The value of expression `index` at (x, y, z); non-finite results read as 0.
  double evaluate(int index, double x, double y, double z);
  size_t size() const { return sources_.size(); }

 private:
  void compile();
  std::vector<std::string> sources_, subjects_;
  std::vector<std::unique_ptr<mu::Parser>> parsers_;
  double x_ = 0, y_ = 0, z_ = 0;  // the parsers' variables
};

}  // namespace limn::render::implicit
