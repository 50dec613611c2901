#pragma once
/// @file
/// The library being loaded, as the plugin loader tells the registries (private to the framework; registry.hpp's
/// registration:: functions are the registries' view of it).

#include <string>
#include <vector>

namespace redres {

/// While a plugin library is being loaded: its path and the registration errors it caused.
struct RegistrationScope {
  std::string library;              //!< the library being loaded
  std::vector<std::string> errors;  //!< e.g. duplicate names
  int added = 0;                    //!< plugins it registered
};

/// The scope of the library being loaded, or nullptr (built-in registration).
RegistrationScope*& current_registration_scope();

}  // namespace redres
