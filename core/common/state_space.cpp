#include "core/common/state_space.h"

namespace flexarm {

bool StateSpace::isValid(std::string* why) const {
  auto fail = [&](const char* msg) {
    if (why) *why = msg;
    return false;
  };
  if (A.rows() != A.cols()) return fail("A is not square");
  if (B.rows() != A.rows()) return fail("B has a different number of rows than A");
  if (C.cols() != A.cols()) return fail("C has a different number of columns than A");
  if (D.rows() != C.rows() || D.cols() != B.cols()) return fail("D does not match C and B");
  if (!A.allFinite() || !B.allFinite() || !C.allFinite() || !D.allFinite())
    return fail("a matrix has a non-finite entry");
  if (sampleTime < 0.0) return fail("negative sample time");
  return true;
}

}  // namespace flexarm
