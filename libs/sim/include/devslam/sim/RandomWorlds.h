#pragma once
/// Seeded random worlds for the navigation benchmark, one generator per category. Every
/// world returned is valid (validateWorld) and has an A* path from start to goal for the
/// given planner options with the world's robot radius (as sim::runEpisode plans); the
/// same (category, seed) always gives the same world.
///
/// Usage:
///   auto w = devslam::sim::randomWorld(devslam::sim::Category::Office, 7, plannerOpts);
#include <devslam/nav/GridPlanner.h>
#include <devslam/sim/World.h>

#include <cstdint>
#include <string>
#include <vector>

namespace devslam::sim {

enum class Category { OpenClutter, CorridorPeople, Office, ObstacleNearGoal };
[[nodiscard]] const char* toString(Category c);
[[nodiscard]] std::vector<Category> allCategories();
/// True for categories whose worlds have moving people.
[[nodiscard]] bool hasPeople(Category c);

/// Throws std::runtime_error if no valid world is found in 200 attempts (never seen).
[[nodiscard]] WorldSpec randomWorld(Category c, uint32_t seed,
                                    const nav::GridPlannerOptions& planner = {});

}  // namespace devslam::sim
