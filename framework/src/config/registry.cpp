#include "redres/config/registry.hpp"

#include <algorithm>
#include <stdexcept>

#include "config/registration_scope.hpp"

namespace redres {

RegistrationScope*& current_registration_scope() {
  static RegistrationScope* scope = nullptr;
  return scope;
}

namespace registration {

std::string origin() {
  const RegistrationScope* scope = current_registration_scope();
  return scope != nullptr ? scope->library : "built-in";
}

void refuse(const std::string& why) {
  RegistrationScope* scope = current_registration_scope();
  if (scope == nullptr) throw std::logic_error(why);
  scope->errors.push_back(why);
}

void added() noexcept {
  if (RegistrationScope* scope = current_registration_scope(); scope != nullptr) ++scope->added;
}

}  // namespace registration

RegistryBase::RegistryBase(std::string kind) : kind_(std::move(kind)) { all().push_back(this); }

RegistryBase::~RegistryBase() {
  auto& v = all();
  v.erase(std::remove(v.begin(), v.end(), this), v.end());
}

std::vector<RegistryBase*>& RegistryBase::all() {
  static std::vector<RegistryBase*> registries;
  return registries;
}

}  // namespace redres
