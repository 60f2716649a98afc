// A ROS map_server map for the OMPL benches: the YAML's image, resolution and origin, and
// the binary PGM's free cells (254), row 0 the bottom row. Shared by ompl_bench.cpp and
// ompl_rs_bench.cpp.
#pragma once

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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
