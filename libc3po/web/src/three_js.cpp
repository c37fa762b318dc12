#include "three_js.hpp"

#include <stdexcept>

#include "embedded_resources.hpp"

namespace c3po::web {

std::string ThreeJsForPage() {
  std::string text = resources::ThreeJsLicense() + resources::ThreeJsModule();
  if (text.find("</script") != std::string::npos) throw std::logic_error("embedded three.js contains </script");
  return text;
}

}  // namespace c3po::web
