// Software License Agreement (BSD-3-Clause)
//
// Copyright 2018 The University of North Carolina at Chapel Hill
//
// Redistribution and use in source and binary forms, with or without
// modification, are permitted provided that the following conditions
// are met:
//
// 1. Redistributions of source code must retain the above copyright
//    notice, this list of conditions and the following disclaimer.
//
// 2. Redistributions in binary form must reproduce the above
//    copyright notice, this list of conditions and the following
//    disclaimer in the documentation and/or other materials provided
//    with the distribution.
//
// 3. Neither the name of the copyright holder nor the names of its
//    contributors may be used to endorse or promote products derived
//    from this software without specific prior written permission.
//
// THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS
// "AS IS" AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT
// LIMITED TO, THE IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS
// FOR A PARTICULAR PURPOSE ARE DISCLAIMED. IN NO EVENT SHALL THE
// COPYRIGHT HOLDER OR CONTRIBUTORS BE LIABLE FOR ANY DIRECT,
// INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR CONSEQUENTIAL DAMAGES
// (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR
// SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS INTERRUPTION)
// HOWEVER CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN CONTRACT,
// STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE)
// ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED
// OF THE POSSIBILITY OF SUCH DAMAGE.

//! @author Jeff Ichnowski

#pragma once
#ifndef NIGH_METRIC_CARTESIAN_SPACE_HPP
#define NIGH_METRIC_CARTESIAN_SPACE_HPP

#include "metric/cartesian.hpp"
#include "metric/cartesian_state_element.hpp"
#include "metric/space_cartesian.hpp"
#include <tuple>

namespace unc::robotics::nigh::impl {
    template <typename Tuple, typename Indices>
    struct cartesian_space_select;

    template <typename Tuple, std::size_t ... I>
    struct cartesian_space_select<Tuple, std::index_sequence<I...>> {
        using type = Space<
            std::tuple<typename std::tuple_element_t<I, Tuple>::Type...>,
            Cartesian<typename std::tuple_element_t<I, Tuple>::Metric...>>;
    };
}

namespace unc::robotics::nigh::metric {
    template <typename ... S>
    using CartesianSpace = typename impl::cartesian_space_select<
        std::tuple<S...>, std::index_sequence_for<S...>>::type;
}

namespace std {
    template <std::size_t I, typename ... S>
    decltype(auto) get(const unc::robotics::nigh::metric::CartesianSpace<S...>& space) {
        return space.template get<I>();
    }
}

#endif
