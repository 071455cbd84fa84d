#include "sha256.hpp"

#include <openssl/evp.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "hila/core/error.hpp"
#include "hila/db/database.hpp"

namespace hila::db {

namespace detail {

struct Sha256::Impl {
  EVP_MD_CTX* ctx = nullptr;
  bool finished = false;
};

Sha256::Sha256() : impl_(std::make_unique<Impl>()) {
  impl_->ctx = EVP_MD_CTX_new();
  // Failures here mean OpenSSL itself is broken (out of memory, no provider): not input errors.
  if (!impl_->ctx || EVP_DigestInit_ex(impl_->ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(impl_->ctx);
    throw std::runtime_error("OpenSSL: cannot initialise SHA-256");
  }
}

Sha256::~Sha256() {
  EVP_MD_CTX_free(impl_->ctx);
}

void Sha256::update(const void* data, std::size_t size) {
  if (impl_->finished) throw std::logic_error("Sha256::update after hex_digest");
  if (size == 0) return;
  if (EVP_DigestUpdate(impl_->ctx, data, size) != 1) {
    throw std::runtime_error("OpenSSL: SHA-256 update failed");
  }
}

std::string Sha256::hex_digest() {
  if (impl_->finished) throw std::logic_error("Sha256::hex_digest called twice");
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int size = 0;
  if (EVP_DigestFinal_ex(impl_->ctx, digest.data(), &size) != 1) {
    throw std::runtime_error("OpenSSL: SHA-256 final failed");
  }
  impl_->finished = true;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * size);
  for (unsigned int i = 0; i < size; ++i) {
    hex.push_back(kHex[digest[i] >> 4]);
    hex.push_back(kHex[digest[i] & 0x0f]);
  }
  return hex;
}

}  // namespace detail

std::string sha256_hex(const std::string& bytes) {
  detail::Sha256 hasher;
  hasher.update(bytes);
  return hasher.hex_digest();
}

std::string sha256_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    throw core::InputError(path, "(file)", "an existing file to hash", "no such file");
  }
  if (std::filesystem::is_directory(status)) {
    throw core::InputError(path, "(file)", "a file to hash", "a directory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw core::InputError(path, "(file)", "a readable file to hash",
                           "a file that cannot be opened");
  detail::Sha256 hasher;
  std::array<char, 1 << 16> buffer{};
  while (in) {
    in.read(buffer.data(), buffer.size());
    hasher.update(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw core::InputError(path, "(file)", "a readable file to hash", "a read error");
  return hasher.hex_digest();
}

}  // namespace hila::db
