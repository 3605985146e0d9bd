// magnetics/source_buffer.cpp — the packed source arrays of source_buffer.hpp.
#include "magnetics/source_buffer.hpp"

namespace magsim::mag::detail {

void SourceBuffer::clear() {
  x.clear(); y.clear(); z.clear(); mx.clear(); my.clear(); mz.clear(); id.clear(); grp.clear();
  rad.clear();
}

void SourceBuffer::push(double px, double py, double pz, double qx, double qy, double qz,
                        double index, double group, double radius) {
  x.push_back(px); y.push_back(py); z.push_back(pz);
  mx.push_back(qx); my.push_back(qy); mz.push_back(qz);
  id.push_back(index); grp.push_back(group < 0 ? -1.0 : group);
  rad.push_back(radius);
}

void SourceBuffer::append(const SourceBuffer& s, std::size_t b, std::size_t e) {
  std::vector<double>* to[9] = {&x, &y, &z, &mx, &my, &mz, &id, &grp, &rad};
  const std::vector<double>* from[9] = {&s.x, &s.y, &s.z, &s.mx, &s.my, &s.mz, &s.id, &s.grp, &s.rad};
  for (int k = 0; k < 9; ++k) to[k]->insert(to[k]->end(), from[k]->begin() + b, from[k]->begin() + e);
}

void SourceBuffer::pad() {
  while (size() % kSourcePad != 0)
    push(kPadPosition, kPadPosition, kPadPosition, 0.0, 0.0, 0.0, -1.0, -1.0, 0.0);
}

}  // namespace magsim::mag::detail
