// OMPL's PRM and RRT-Connect, in C++ as OMPL's users run them, on a ROS map_server map:
// one JSON line per run (time to the first solution, raw and simplified path length).
//
//   g++ -O2 -std=c++17 tools/ompl_bench.cpp -I/usr/include/ompl-1.5 -I/usr/include/eigen3 -lompl -o ompl_bench
//   ompl_bench MAP.yaml prm|rrt-connect RUNS SEED X0 Y0 X1 Y1 [TIMEOUT_S] [RRT_RANGE_M]
//
// The state space is the map's rectangle; a state is valid when its cell is free (254 in
// map_server's trinary PGM). Motions are checked every half cell, as forkbench's cell walk.
// The clock runs from `solve` to its first exact solution (an exact-solution termination
// condition beside the timeout); setup happens before. Runs share one seeded RNG stream.
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "ompl_map.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace ob = ompl::base;
namespace og = ompl::geometric;

int main(int argc, char **argv) {
    if (argc < 9) {
        std::cerr << "usage: ompl_bench MAP.yaml prm|rrt-connect RUNS SEED X0 Y0 X1 Y1 [TIMEOUT_S] [RRT_RANGE_M]\n";
        return 2;
    }
    std::string planner = argv[2];
    int runs = std::atoi(argv[3]);
    double x0 = std::atof(argv[5]), y0 = std::atof(argv[6]), x1 = std::atof(argv[7]), y1 = std::atof(argv[8]);
    double timeout_s = argc > 9 ? std::atof(argv[9]) : 10.0;
    double range_m = argc > 10 ? std::atof(argv[10]) : 1.0;
    Grid g;
    std::string image;
    if (!read_yaml(argv[1], image, g.res, g.ox, g.oy) || !read_pgm(image, g)) {
        std::cerr << argv[1] << ": not a map_server map (YAML with image, resolution, origin; P5 PGM)\n";
        return 2;
    }
    if (planner != "prm" && planner != "rrt-connect") {
        std::cerr << "planner " << planner << ": prm or rrt-connect\n";
        return 2;
    }
    ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
    ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(std::atol(argv[4])) + 1);

    auto space = std::make_shared<ob::RealVectorStateSpace>(2);
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, g.ox);
    bounds.setHigh(0, g.ox + g.w * g.res);
    bounds.setLow(1, g.oy);
    bounds.setHigh(1, g.oy + g.h * g.res);
    space->setBounds(bounds);
    for (int run = 0; run < runs; ++run) {
        og::SimpleSetup ss(space);
        ss.setStateValidityChecker([&g](const ob::State *s) {
            const auto *v = s->as<ob::RealVectorStateSpace::StateType>();
            return g.is_free(v->values[0], v->values[1]);
        });
        auto si = ss.getSpaceInformation();
        si->setStateValidityCheckingResolution(0.5 * g.res / space->getMaximumExtent());
        ob::ScopedState<> start(space), goal(space);
        start[0] = x0;
        start[1] = y0;
        goal[0] = x1;
        goal[1] = y1;
        ss.setStartAndGoalStates(start, goal);
        if (planner == "prm") {
            ss.setPlanner(std::make_shared<og::PRM>(si));
        } else {
            auto p = std::make_shared<og::RRTConnect>(si);
            p->setRange(range_m);
            ss.setPlanner(p);
        }
        ss.setup();
        auto ptc = ob::plannerOrTerminationCondition(ob::timedPlannerTerminationCondition(timeout_s),
                                                     ob::exactSolnPlannerTerminationCondition(ss.getProblemDefinition()));
        auto t0 = std::chrono::steady_clock::now();
        ob::PlannerStatus status = ss.solve(ptc);
        double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        bool ok = status == ob::PlannerStatus::EXACT_SOLUTION;
        double length = ok ? ss.getSolutionPath().length() : -1.0;
        double simplified = -1.0, simplify_s = 0.0;
        if (ok) {
            auto t1 = std::chrono::steady_clock::now();
            ss.simplifySolution();
            simplify_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
            simplified = ss.getSolutionPath().length();
        }
        std::printf("{\"run\":%d,\"success\":%s,\"time_s\":%.9f,\"length_m\":%.6f,\"simplified_length_m\":%.6f,\"simplify_s\":%.9f}\n",
                    run, ok ? "true" : "false", time_s, length, simplified, simplify_s);
    }
    return 0;
}
