// TEMPORARY (lead): replaced by the models helper.
#pragma once
#include "models/turing.hpp"
#include <tuple>
namespace morphogen {
using AllModels = std::tuple<models::Turing>;
}
