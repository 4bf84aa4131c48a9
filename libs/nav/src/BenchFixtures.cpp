#include <devslam/nav/BenchFixtures.h>

namespace devslam::nav {

mrpt::maps::COccupancyGridMap2D clutteredGrid400() {
    mrpt::maps::COccupancyGridMap2D grid;
    grid.setSize(0, 20, 0, 20, 0.05f, 1.0f);
    std::mt19937 g(5);
    std::uniform_real_distribution<double> u(2.0, 18.0);
    for (int k = 0; k < 60; k++) {
        const double cx = u(g), cy = u(g);
        for (double y = cy - 0.5; y <= cy + 0.5; y += 0.05)
            for (double x = cx - 0.5; x <= cx + 0.5; x += 0.05) grid.setPos(x, y, 0.0f);
    }
    return grid;
}

VfhInput randomVfhInput(std::mt19937& g) {
    std::uniform_real_distribution<double> u(0.05, 1.0);
    VfhInput in;
    in.obstacles.resize(121);
    for (auto& d : in.obstacles) d = u(g);
    in.target_x = 0.6;
    in.target_y = 0.2;
    in.ref_distance = 2.5;
    return in;
}

}  // namespace devslam::nav
