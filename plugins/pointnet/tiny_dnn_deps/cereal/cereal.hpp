#pragma once
// c3po's stand-in for the cereal serialisation library (not a copy of it).
//
// Debian's tiny-dnn 1.0.0a3 headers include <cereal/...> unconditionally, but
// the package does not depend on libcereal-dev. c3po never uses tiny-dnn's own
// serialisation (the pointnet model file is written by c3po, see
// model_file.cpp) and compiles tiny-dnn with CNN_NO_SERIALIZATION, so the
// headers only need these declarations to parse. Every archive throws if it is
// ever constructed, so an accidental use fails loudly instead of silently.
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <utility>

#define CEREAL_SERIALIZE_FUNCTION_NAME serialize
#define CEREAL_NVP(T) ::cereal::make_nvp(#T, T)

namespace cereal {

using size_type = std::uint64_t;

template <class T>
struct NameValuePair {
  const char* name;
  T value;
};

template <class T>
NameValuePair<T&> make_nvp(const char* name, T& value) {
  return {name, value};
}
template <class T>
NameValuePair<const T&> make_nvp(const char* name, const T& value) {
  return {name, value};
}

template <class T>
struct SizeTag {
  T size;
};
template <class T>
SizeTag<T&> make_size_tag(T& size) {
  return {size};
}
template <class T>
SizeTag<T> make_size_tag(T&& size) {
  return {std::forward<T>(size)};
}

template <class T>
class construct {
 public:
  template <class... Args>
  void operator()(Args&&...) {
    throw std::logic_error("cereal stand-in: tiny-dnn deserialisation is disabled in c3po");
  }
};

namespace detail {
class UnavailableArchive {
 public:
  template <class Stream>
  explicit UnavailableArchive(Stream&) {
    throw std::logic_error("cereal stand-in: tiny-dnn serialisation is disabled in c3po");
  }
  template <class... T>
  UnavailableArchive& operator()(T&&...) { return *this; }
  void startNode() {}
  void finishNode() {}
};
}  // namespace detail

class JSONInputArchive : public detail::UnavailableArchive {
 public:
  explicit JSONInputArchive(std::istream& in) : UnavailableArchive(in) {}
};
class JSONOutputArchive : public detail::UnavailableArchive {
 public:
  explicit JSONOutputArchive(std::ostream& out) : UnavailableArchive(out) {}
};
class BinaryInputArchive : public detail::UnavailableArchive {
 public:
  explicit BinaryInputArchive(std::istream& in) : UnavailableArchive(in) {}
};
class BinaryOutputArchive : public detail::UnavailableArchive {
 public:
  explicit BinaryOutputArchive(std::ostream& out) : UnavailableArchive(out) {}
};

namespace memory_detail {
template <class Archive, class T>
struct LoadAndConstructLoadWrapper {
  explicit LoadAndConstructLoadWrapper(T*) {}
  template <class A>
  void serialize(A&) {
    throw std::logic_error("cereal stand-in: tiny-dnn deserialisation is disabled in c3po");
  }
};
}  // namespace memory_detail

}  // namespace cereal
