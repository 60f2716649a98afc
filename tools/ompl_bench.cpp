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

struct Grid {
    int w = 0, h = 0;
    double res = 0, ox = 0, oy = 0;
    std::vector<unsigned char> free;  // row 0 is the bottom row
    bool is_free(double x, double y) const {
        int c = static_cast<int>((x - ox) / res), r = static_cast<int>((y - oy) / res);
        return x >= ox && y >= oy && c < w && r < h && free[r * w + c];
    }
};

// The YAML's image, resolution and origin (the keys map_server writes, one per line).
static bool read_yaml(const std::string &path, std::string &image, double &res, double &ox, double &oy) {
    std::ifstream in(path);
    std::string line;
    bool got_image = false, got_res = false, got_origin = false;
    int origin_items = -1;  // origin as a block list: the items still to read
    while (std::getline(in, line)) {
        auto dash = line.find_first_not_of(' ');
        if (origin_items > 0 && dash != std::string::npos && line[dash] == '-') {
            double v = 0;
            if (!(std::istringstream(line.substr(dash + 1)) >> v)) return false;
            (origin_items == 2 ? ox : oy) = v;
            got_origin = --origin_items == 0;
            continue;
        }
        auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string key = line.substr(0, colon), value = line.substr(colon + 1);
        if (key == "image") {
            std::istringstream(value) >> image;
            got_image = true;
        } else if (key == "resolution") {
            got_res = static_cast<bool>(std::istringstream(value) >> res);
        } else if (key == "origin") {
            got_origin = std::sscanf(value.c_str(), " [ %lf , %lf", &ox, &oy) == 2;
            if (value.find_first_not_of(' ') == std::string::npos) origin_items = 2;
        }
    }
    if (!image.empty() && image[0] != '/') {
        auto slash = path.rfind('/');
        image = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + image;
    }
    return got_image && got_res && got_origin && res > 0;
}

// A binary PGM (P5, maxval 255), `#` comments allowed in the header.
static bool read_pgm(const std::string &path, Grid &g) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    int fields[3], n = 0;
    in >> magic;
    while (n < 3 && in) {
        in >> std::ws;
        if (in.peek() == '#') {
            std::string skip;
            std::getline(in, skip);
            continue;
        }
        in >> fields[n++];
    }
    if (magic != "P5" || n < 3 || fields[2] != 255 || fields[0] <= 0 || fields[1] <= 0) return false;
    in.get();
    g.w = fields[0];
    g.h = fields[1];
    std::vector<unsigned char> data(static_cast<size_t>(g.w) * g.h);
    in.read(reinterpret_cast<char *>(data.data()), static_cast<std::streamsize>(data.size()));
    if (!in) return false;
    g.free.resize(data.size());
    for (int r = 0; r < g.h; ++r)
        for (int c = 0; c < g.w; ++c) g.free[r * g.w + c] = data[(g.h - 1 - r) * g.w + c] == 254;
    return true;
}

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
