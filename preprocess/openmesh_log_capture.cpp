// OpenMesh's omerr()/omout()/omlog() are std::ostreams over a multiplexing buffer that
// forwards whole lines to std::cerr/cout/clog. Once per process a routing buffer is put in
// front of each multiplexer: it appends to the writing thread's capture when that thread has
// one, and otherwise passes every character straight on to the multiplexer, so for everybody
// else the streams behave exactly as before. (Connecting a target of our own to the
// multiplexers instead would leak: mostream::disconnect never frees what connect allocated;
// and disable() would drop other threads' messages too.)
#include "preprocess/openmesh_log_capture.h"

#include <OpenMesh/Core/System/omstream.hh>

#include <mutex>
#include <streambuf>

namespace lod::detail {
namespace {

thread_local std::string* tls_capture = nullptr;

class RoutingBuf final : public std::streambuf {
 public:
  RoutingBuf(const OpenMesh::mostream* stream, std::streambuf* next) : stream_(stream), next_(next) {}

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    if (tls_capture) {
      if (stream_->is_enabled()) tls_capture->push_back(traits_type::to_char_type(c));
      return c;
    }
    return next_ ? next_->sputc(traits_type::to_char_type(c)) : c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (tls_capture) {
      if (stream_->is_enabled()) tls_capture->append(s, size_t(n));
      return n;
    }
    return next_ ? next_->sputn(s, n) : n;
  }
  int sync() override { return tls_capture || !next_ ? 0 : next_->pubsync(); }

 private:
  // A disabled stream (OpenMesh's omlog() in release builds, or one the host turned off)
  // stays silent in captures too: a capture sees what the terminal would have.
  const OpenMesh::mostream* stream_;
  std::streambuf* next_;  // OpenMesh's multiplexer (it lives as long as its stream)
};

// Never destroyed: OpenMesh's streams are function statics that may be written to during
// static destruction, after anything of ours with a destructor would be gone.
void install_routers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (OpenMesh::mostream* s : {&::omerr(), &::omout(), &::omlog()}) {
      s->flush();  // a partial line someone left belongs to them, not to the first capture
      auto* router = new RoutingBuf(s, s->rdbuf());
      s->rdbuf(router);
    }
  });
}

}  // namespace

OpenMeshLogCapture::OpenMeshLogCapture() {
  install_routers();
  previous_ = tls_capture;
  tls_capture = &raw_;
}

OpenMeshLogCapture::~OpenMeshLogCapture() { tls_capture = previous_; }

std::string OpenMeshLogCapture::text() const {
  std::string out;
  for (char c : raw_) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    if (!(c == ' ' && (out.empty() || out.back() == ' '))) out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  if (out.size() > 300) out = out.substr(0, 297) + "...";
  return out;
}

}  // namespace lod::detail
