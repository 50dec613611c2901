#include "redres/registry.hpp"

#include <algorithm>

namespace redres {

RegistrationScope*& current_registration_scope() {
  static RegistrationScope* scope = nullptr;
  return scope;
}

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
