#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include "api/obj_reader.h"
#include "render/rules/limit.h"
#include "render/rules/refine.h"
#include "render/tessellate/tessellate.h"
using namespace limn;
using namespace limn::render;
static double ms(std::chrono::steady_clock::time_point a){return std::chrono::duration<double,std::milli>(std::chrono::steady_clock::now()-a).count();}
int main(int argc,char**argv){
  std::ifstream f(argv[1]); std::stringstream s; s<<f.rdbuf();
  auto mesh=api::readObj(s.str(), mesh::Scheme::CatmullClark, {}).mesh;
  int level=std::atoi(argv[2]);
  auto t=std::chrono::steady_clock::now();
  auto L=rules::refineUniform(mesh,level,rules::Method::Masks); printf("refine %.0f ms (%zu verts)\n",ms(t),L.points.size());
  t=std::chrono::steady_clock::now();
  auto lim=rules::limitOf(L); printf("limit %.0f ms\n",ms(t));
  subdiv::LimitSurface surf(mesh);
  tessellate::UniformOptions o; o.level=level; o.engine=tessellate::UniformEngine::Masks;
  t=std::chrono::steady_clock::now();
  auto tm=tessellate::tessellateUniform(surf,o); printf("total masks %.0f ms\n",ms(t));
  o.engine=tessellate::UniformEngine::OpenSubdiv;
  t=std::chrono::steady_clock::now();
  tm=tessellate::tessellateUniform(surf,o); printf("total osd %.0f ms\n",ms(t));
}
