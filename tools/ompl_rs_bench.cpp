// OMPL's RRT* and BIT* over OMPL's ReedsSheppStateSpace, in C++ as OMPL's users run them,
// on a ROS map_server map with the truck's footprint: the anchor for forkbench's Hybrid-A*.
// Pose pairs come on standard input, one per line (x0 y0 heading0 x1 y1 heading1, radians);
// one JSON line per pair: time to the first exact solution, its length and cusps, and its
// length after 1 s of planning (the same planner continued).
//
//   g++ -O2 -std=c++17 tools/ompl_rs_bench.cpp -I/usr/include/ompl-1.5 -I/usr/include/eigen3 -lompl -o ompl_rs_bench
//   ompl_rs_bench MAP.yaml rrtstar|bitstar SEED RADIUS_M MARGIN_M BODY_L BODY_W FORK_L FORK_W [TIMEOUT_S]
//
// A pose is valid when neither rectangle (chassis behind the fork root, forks ahead, each
// grown by the margin) covers the centre of a non-free cell, the rectangles grown by half a
// cell's diagonal so a cell they touch counts. Motions are checked every 5 cm.
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/ReedsSheppStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "ompl_map.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace ob = ompl::base;
namespace og = ompl::geometric;


struct Rect {
    double length, width, ahead;
};

// Whether a rectangle placed relative to the pose (x, y, th) covers a non-free cell centre.
static bool rect_hits(const Grid &g, const Rect &r, double x, double y, double th) {
    double c = std::cos(th), s = std::sin(th);
    double cx = x + r.ahead * c, cy = y + r.ahead * s;
    double pad = 0.5 * g.res * std::sqrt(2.0);
    double hl = 0.5 * r.length + pad, hw = 0.5 * r.width + pad;
    double ex = std::abs(hl * c) + std::abs(hw * s), ey = std::abs(hl * s) + std::abs(hw * c);
    int c0 = static_cast<int>(std::floor((cx - ex - g.ox) / g.res)), c1 = static_cast<int>(std::floor((cx + ex - g.ox) / g.res));
    int r0 = static_cast<int>(std::floor((cy - ey - g.oy) / g.res)), r1 = static_cast<int>(std::floor((cy + ey - g.oy) / g.res));
    for (int row = std::max(r0, 0); row <= std::min(r1, g.h - 1); ++row)
        for (int col = std::max(c0, 0); col <= std::min(c1, g.w - 1); ++col) {
            if (g.free[row * g.w + col]) continue;
            double px = g.ox + (col + 0.5) * g.res - cx, py = g.oy + (row + 0.5) * g.res - cy;
            double along = px * c + py * s, across = -px * s + py * c;
            if (std::abs(along) <= hl && std::abs(across) <= hw) return true;
        }
    return false;
}

// Direction changes along a solution: each piece's Reeds-Shepp segments in turn.
static int cusps(const ob::ReedsSheppStateSpace &rs, const og::PathGeometric &path) {
    int count = 0, last = 0;
    for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i) {
        auto p = rs.reedsShepp(path.getState(i), path.getState(i + 1));
        for (double len : p.length_) {
            if (std::abs(len) < 1e-9) continue;
            int dir = len > 0 ? 1 : -1;
            if (last != 0 && dir != last) ++count;
            last = dir;
        }
    }
    return count;
}

int main(int argc, char **argv) {
    if (argc < 10) {
        std::cerr << "usage: ompl_rs_bench MAP.yaml rrtstar|bitstar SEED RADIUS_M MARGIN_M BODY_L BODY_W FORK_L FORK_W [TIMEOUT_S]\n";
        return 2;
    }
    std::string planner = argv[2];
    double radius = std::atof(argv[4]), margin = std::atof(argv[5]);
    Rect body{std::atof(argv[6]) + 2 * margin, std::atof(argv[7]) + 2 * margin, -0.5 * std::atof(argv[6])};
    Rect forks{std::atof(argv[8]) + 2 * margin, std::atof(argv[9]) + 2 * margin, 0.5 * std::atof(argv[8])};
    double timeout_s = argc > 10 ? std::atof(argv[10]) : 10.0;
    Grid g;
    std::string image;
    if (!read_yaml(argv[1], image, g.res, g.ox, g.oy) || !read_pgm(image, g)) {
        std::cerr << argv[1] << ": not a map_server map (YAML with image, resolution, origin; P5 PGM)\n";
        return 2;
    }
    if (planner != "rrtstar" && planner != "bitstar") {
        std::cerr << "planner " << planner << ": rrtstar or bitstar\n";
        return 2;
    }
    ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
    ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(std::atol(argv[3])) + 1);
    auto space = std::make_shared<ob::ReedsSheppStateSpace>(radius);
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, g.ox);
    bounds.setHigh(0, g.ox + g.w * g.res);
    bounds.setLow(1, g.oy);
    bounds.setHigh(1, g.oy + g.h * g.res);
    space->setBounds(bounds);
    double x0, y0, t0, x1, y1, t1;
    for (int pair = 0; std::cin >> x0 >> y0 >> t0 >> x1 >> y1 >> t1; ++pair) {
        og::SimpleSetup ss(space);
        ss.setStateValidityChecker([&](const ob::State *st) {
            const auto *v = st->as<ob::SE2StateSpace::StateType>();
            return !rect_hits(g, body, v->getX(), v->getY(), v->getYaw()) &&
                   !rect_hits(g, forks, v->getX(), v->getY(), v->getYaw());
        });
        auto si = ss.getSpaceInformation();
        si->setStateValidityCheckingResolution(0.05 / space->getMaximumExtent());
        ob::ScopedState<ob::SE2StateSpace> start(space), goal(space);
        start->setXY(x0, y0);
        start->setYaw(t0);
        goal->setXY(x1, y1);
        goal->setYaw(t1);
        ss.setStartAndGoalStates(start, goal, 0.05);
        ss.setOptimizationObjective(std::make_shared<ob::PathLengthOptimizationObjective>(si));
        if (planner == "rrtstar")
            ss.setPlanner(std::make_shared<og::RRTstar>(si));
        else
            ss.setPlanner(std::make_shared<og::BITstar>(si));
        // RRT* and BIT* report a solution to the problem only when `solve` returns; their
        // intermediate-solution callback says when the first one is found.
        bool found = false;
        ss.getProblemDefinition()->setIntermediateSolutionCallback(
            [&found](const ob::Planner *, const std::vector<const ob::State *> &, const ob::Cost) { found = true; });
        ss.setup();
        auto ptc = ob::plannerOrTerminationCondition(ob::timedPlannerTerminationCondition(timeout_s),
                                                     ob::PlannerTerminationCondition([&found] { return found; }));
        auto clock0 = std::chrono::steady_clock::now();
        ob::PlannerStatus status = ss.solve(ptc);
        double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
        bool ok = status == ob::PlannerStatus::EXACT_SOLUTION;
        double length = -1, after = -1;
        int n_cusps = -1;
        if (ok) {
            length = ss.getSolutionPath().length();
            n_cusps = cusps(*space, ss.getSolutionPath());
            if (time_s < 1.0) ss.solve(ob::timedPlannerTerminationCondition(1.0 - time_s));
            after = ss.getProblemDefinition()->getSolutionPath()->as<og::PathGeometric>()->length();
        }
        std::printf("{\"pair\":%d,\"success\":%s,\"time_s\":%.9f,\"length_m\":%.6f,\"cusps\":%d,\"length_after_1s_m\":%.6f}\n",
                    pair, ok ? "true" : "false", time_s, length, n_cusps, after);
        std::fflush(stdout);
    }
    return 0;
}
