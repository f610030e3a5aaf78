// The list of every reaction model, in the order they are listed to users (Turing first).
// Code that dispatches on a model name iterates over this tuple.
#pragma once

#include <tuple>

#include "models/barkley.hpp"
#include "models/brusselator.hpp"
#include "models/fitzhugh_nagumo.hpp"
#include "models/gierer_meinhardt.hpp"
#include "models/gray_scott.hpp"
#include "models/gray_scott_sims.hpp"
#include "models/meinhardt.hpp"
#include "models/oregonator.hpp"
#include "models/schnakenberg.hpp"
#include "models/turing.hpp"

namespace morphogen {

using AllModels = std::tuple<models::Turing, models::GrayScott, models::GrayScottSims,
                             models::Brusselator, models::GiererMeinhardt, models::Meinhardt,
                             models::Schnakenberg, models::FitzHughNagumo, models::Barkley,
                             models::BarkleyTurbulent, models::Oregonator>;

} // namespace morphogen
