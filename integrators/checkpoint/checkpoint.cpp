#include "integrators/checkpoint/checkpoint.hpp"

#include "lib/io/result_folder.hpp"
#include "lib/io/run_info.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace shelldyn {
namespace {

using Json = nlohmann::json;
constexpr const char* kFormat = "shelldyn-checkpoint";

// Raw little-endian doubles (x86-64 and every platform Debian builds shelldyn for are little-endian).
Json bytes_of(const Eigen::VectorXd& v) {
  std::vector<std::uint8_t> b(sizeof(double) * static_cast<size_t>(v.size()));
  if (!b.empty()) std::memcpy(b.data(), v.data(), b.size());
  return Json::binary(std::move(b));
}

Eigen::VectorXd vector_of(const Json& j, const std::string& what) {
  if (!j.is_binary()) throw std::runtime_error("vector '" + what + "' is not a byte string");
  const auto& b = j.get_binary();
  if (b.size() % sizeof(double) != 0) throw std::runtime_error("vector '" + what + "' has a partial value");
  Eigen::VectorXd v(static_cast<Eigen::Index>(b.size() / sizeof(double)));
  if (!b.empty()) std::memcpy(v.data(), b.data(), b.size());
  return v;
}

Json map_of_vectors(const std::map<std::string, Eigen::VectorXd>& m) {
  Json j = Json::object();
  for (const auto& [k, v] : m) j[k] = bytes_of(v);
  return j;
}

std::map<std::string, Eigen::VectorXd> vectors_of(const Json& j) {
  std::map<std::string, Eigen::VectorXd> m;
  for (auto it = j.begin(); it != j.end(); ++it) m[it.key()] = vector_of(it.value(), it.key());
  return m;
}

// Doubles as 8-byte strings too: CBOR would keep them exact, but NaN payloads and -0 survive only so.
Json map_of_numbers(const std::map<std::string, double>& m) {
  Json j = Json::object();
  for (const auto& [k, x] : m) j[k] = bytes_of(Eigen::VectorXd::Constant(1, x));
  return j;
}

std::map<std::string, double> numbers_of(const Json& j) {
  std::map<std::string, double> m;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const Eigen::VectorXd v = vector_of(it.value(), it.key());
    if (v.size() != 1) throw std::runtime_error("number '" + it.key() + "' is not one value");
    m[it.key()] = v[0];
  }
  return m;
}

}  // namespace

double Checkpoint::number(const std::string& key) const {
  const auto it = numbers.find(key);
  if (it == numbers.end()) throw std::runtime_error("checkpoint: number '" + key + "' is missing");
  return it->second;
}
const std::string& Checkpoint::text(const std::string& key) const {
  const auto it = texts.find(key);
  if (it == texts.end()) throw std::runtime_error("checkpoint: text '" + key + "' is missing");
  return it->second;
}
const Eigen::VectorXd& Checkpoint::vector(const std::string& key) const {
  const auto it = vectors.find(key);
  if (it == vectors.end()) throw std::runtime_error("checkpoint: vector '" + key + "' is missing");
  return it->second;
}

void check_checkpoint_origin(const Checkpoint& c, const std::string& path, bool allow_changed_case,
                             bool allow_other_version, std::ostream* note) {
  if (c.made_by.empty()) {  // format 1: no checksum, no version
    if (!allow_other_version)
      throw std::runtime_error(path + ": written by a shelldyn whose checkpoints carry no checksum, so its integrity cannot "
                               "be checked; rerun from the start, or add --allow-other-version to continue anyway");
    if (note) *note << "note: " << path << ": a checkpoint without checksum (older shelldyn), continued unchecked" << std::endl;
  } else if (c.made_by != shelldyn_version()) {
    if (!allow_other_version)
      throw std::runtime_error(path + ": written by shelldyn " + c.made_by + ", this is " + shelldyn_version() +
                               "; resume with that version, or add --allow-other-version (the continuation may then "
                               "differ from an uninterrupted run)");
    if (note) *note << "note: " << path << ": written by shelldyn " << c.made_by << ", continued by " << shelldyn_version() << std::endl;
  }
  const auto src = c.texts.find("case_source");
  const auto text = c.texts.find("case_text");
  if (src == c.texts.end() || text == c.texts.end() || src->second.empty()) return;
  std::ifstream in(src->second, std::ios::binary);
  if (!in) {
    if (note) *note << "note: " << src->second << " (the case file) is gone; continuing with the case text the checkpoint keeps" << std::endl;
    return;
  }
  const std::string now((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (now == text->second) return;
  if (!allow_changed_case)
    throw std::runtime_error(src->second + ": the case file was edited after the run in " +
                             std::filesystem::path(path).parent_path().string() +
                             " started; rerun from the start, or add --allow-changed-case to continue the run as it started");
  if (note) *note << "note: " << src->second << " was edited since the run started; continuing with the case text the checkpoint keeps" << std::endl;
}

std::string content_hash(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  Json j;
  j["format"] = kFormat;
  j["version"] = Checkpoint::kVersion;
  Json& s = j["state"];
  s["t"] = bytes_of(Eigen::VectorXd::Constant(1, c.state.t));
  s["u"] = bytes_of(c.state.u);
  s["v"] = bytes_of(c.state.v);
  s["a"] = bytes_of(c.state.a);
  s["pdot"] = bytes_of(c.state.pdot);  // empty unless the integrator embeds director velocities
  std::vector<int> charts;
  charts.reserve(4 * c.state.charts.size());
  for (const auto& ch : c.state.charts) {
    charts.push_back(ch.n);
    charts.push_back(ch.m);
    charts.push_back(ch.l);
    charts.push_back(ch.s > 0 ? 1 : -1);
  }
  s["charts"] = charts;
  Json& in = j["integrator"];
  in["name"] = c.integrator;
  in["exact"] = c.integrator_data.exact;
  in["scalars"] = map_of_numbers(c.integrator_data.scalars);
  in["vectors"] = map_of_vectors(c.integrator_data.vectors);
  j["numbers"] = map_of_numbers(c.numbers);
  j["texts"] = c.texts;
  j["vectors"] = map_of_vectors(c.vectors);
  // The integrity wrapper (checkpoint.hpp): the document as a byte string with its checksum.
  std::vector<std::uint8_t> body = Json::to_cbor(j);
  const auto ct = c.texts.find("case_text");
  const std::string made_by = shelldyn_version();
  const std::string case_hash = content_hash(ct == c.texts.end() ? std::string() : ct->second);
  const std::string sum = content_hash(made_by + "\n" + case_hash + "\n" + std::string(body.begin(), body.end()));
  Json w;
  w["format"] = kFormat;
  w["version"] = Checkpoint::kVersion;
  w["shelldyn"] = made_by;
  w["case_hash"] = case_hash;
  w["checksum"] = sum;
  w["body"] = Json::binary(std::move(body));
  const std::vector<std::uint8_t> cbor = Json::to_cbor(w);
  write_text_atomically(path, std::string(cbor.begin(), cbor.end()), "checkpoint");
}

Checkpoint read_checkpoint(const std::string& path) {
  require_regular_file(path, "checkpoint");  // a FIFO would block the open forever
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) throw std::runtime_error(path + ": cannot read the checkpoint (permission denied?)");
    // Why there is none (the run completed, wrote none, ...): lib/io/result_folder.hpp.
    throw std::runtime_error(explain_missing_checkpoint(std::filesystem::path(path).parent_path().string()));
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    const Json w = Json::from_cbor(bytes);
    if (!w.is_object() || w.value("format", "") != kFormat)
      throw std::runtime_error("not a shelldyn checkpoint");
    const int version = w.at("version").get<int>();
    if (version != Checkpoint::kVersion && version != 1)
      throw std::runtime_error("checkpoint version " + std::to_string(version) + ", this shelldyn reads " +
                               std::to_string(Checkpoint::kVersion));
    Json j;
    std::string made_by;
    if (version == 1) {  // written before checksums: read as it is
      j = w;
    } else {
      made_by = w.at("shelldyn").get<std::string>();
      const std::string case_hash = w.at("case_hash").get<std::string>();
      const auto& body = w.at("body").get_binary();
      const std::string sum = content_hash(made_by + "\n" + case_hash + "\n" + std::string(body.begin(), body.end()));
      if (sum != w.at("checksum").get<std::string>()) throw Json::other_error::create(599, "checksum mismatch", nullptr);
      j = Json::from_cbor(body);
      if (!j.is_object()) throw std::runtime_error("not a shelldyn checkpoint");
      const auto texts = j.at("texts");
      if (content_hash(texts.value("case_text", std::string())) != case_hash)
        throw Json::other_error::create(599, "case hash mismatch", nullptr);
    }
    Checkpoint c;
    c.made_by = made_by;
    const Json& s = j.at("state");
    const Eigen::VectorXd t = vector_of(s.at("t"), "t");
    if (t.size() != 1) throw std::runtime_error("state.t is not one value");
    c.state.t = t[0];
    c.state.u = vector_of(s.at("u"), "u");
    c.state.v = vector_of(s.at("v"), "v");
    c.state.a = vector_of(s.at("a"), "a");
    c.state.pdot = vector_of(s.at("pdot"), "pdot");
    const auto charts = s.at("charts").get<std::vector<int>>();
    if (charts.size() % 4 != 0) throw std::runtime_error("state.charts is truncated");
    for (size_t k = 0; k < charts.size(); k += 4) {
      DirectorChart ch;
      ch.n = charts[k], ch.m = charts[k + 1], ch.l = charts[k + 2], ch.s = charts[k + 3];
      check_chart(ch);
      c.state.charts.push_back(ch);
    }
    const Json& ij = j.at("integrator");
    c.integrator = ij.at("name").get<std::string>();
    c.integrator_data.exact = ij.at("exact").get<bool>();
    c.integrator_data.scalars = numbers_of(ij.at("scalars"));
    c.integrator_data.vectors = vectors_of(ij.at("vectors"));
    c.numbers = numbers_of(j.at("numbers"));
    c.texts = j.at("texts").get<std::map<std::string, std::string>>();
    c.vectors = vectors_of(j.at("vectors"));
    return c;
  } catch (const nlohmann::json::exception& e) {
    std::string why = e.what();  // "[json.exception.other_error.599] checksum mismatch" -> "checksum mismatch"
    if (const auto b = why.find("] "); b != std::string::npos) why = why.substr(b + 2);
    if (why.size() > 60) why = why.substr(0, 57) + "...";
    throw std::runtime_error(path + ": damaged checkpoint; rerun from the start (" + why + ")");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": damaged checkpoint; rerun from the start\n" + std::string(e.what()));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace shelldyn
