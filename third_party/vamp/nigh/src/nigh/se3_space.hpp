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
#ifndef NIGH_METRIC_SE3_HPP
#define NIGH_METRIC_SE3_HPP

#include "lp_space.hpp"
#include "so3_space.hpp"
#include "scaled_space.hpp"
#include "cartesian_space.hpp"

namespace unc::robotics::nigh::impl {
    template <typename Scalar, std::intmax_t so3weight, std::intmax_t l2weight>
    struct se3_space_selector {
        static_assert(so3weight >= 1 && l2weight >= 1, "weights must be positive");

        using type = metric::CartesianSpace<
            metric::ScaledSpace<SO3Space<Scalar>, std::ratio<so3weight>>,
            metric::ScaledSpace<L2Space<Scalar, 3>, std::ratio<l2weight>>>;
    };

    template <typename Scalar, std::intmax_t so3weight>
    struct se3_space_selector<Scalar, so3weight, 1> {
        using type = metric::CartesianSpace<
            metric::ScaledSpace<SO3Space<Scalar>, std::ratio<so3weight>>,
            metric::L2Space<Scalar, 3>>;
    };

    template <typename Scalar, std::intmax_t l2weight>
    struct se3_space_selector<Scalar, 1, l2weight> {
        using type = metric::CartesianSpace<
            metric::SO3Space<Scalar>,
            metric::ScaledSpace<L2Space<Scalar, 3>, std::ratio<l2weight>>>;
    };

    template <typename Scalar>
    struct se3_space_selector<Scalar, 1, 1> {
        using type = metric::CartesianSpace<SO3Space<Scalar>, L2Space<Scalar, 3>>;
    };
}

namespace unc::robotics::nigh::metric {
    template <typename Scalar, std::intmax_t so3weight = 1, std::intmax_t l2weight = 1>
    using SE3Space = typename impl::se3_space_selector<Scalar, so3weight, l2weight>::type;

    template <typename Scalar, typename Weight = Scalar>
    using ScaledSE3Space = metric::CartesianSpace<
        ScaledSpace<SO3Space<Scalar>, Weight>,
        L2Space<Scalar, 3>>;
}

#endif
