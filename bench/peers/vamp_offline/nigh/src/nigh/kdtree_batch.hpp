// cellplan bench/peers stand-in: everything is in nigh_forward.hpp.
#pragma once
#include "nigh_forward.hpp"
