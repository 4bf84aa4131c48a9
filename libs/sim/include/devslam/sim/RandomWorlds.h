#pragma once
/// Seeded random worlds for the navigation benchmark, one generator per category. Every
/// world returned is valid (validateWorld) and has an A* path from start to goal for the
/// given planner options with the world's robot radius (as sim::runEpisode plans); the
/// same (category, seed) always gives the same world.
///
/// Usage:
///   auto w = devslam::sim::randomWorld(devslam::sim::Category::Office, 7, plannerOpts);
#include <devslam/nav/GridPlanner.h>
#include <devslam/sim/Episode.h>
#include <devslam/sim/World.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace devslam::sim {

enum class Category { OpenClutter, CorridorPeople, Office, ObstacleNearGoal };
[[nodiscard]] const char* toString(Category c);
[[nodiscard]] std::vector<Category> allCategories();
/// The category whose toString() is `name`; none for another name.
[[nodiscard]] std::optional<Category> categoryNamed(const std::string& name);
/// "open_clutter, corridor_people, ...": every category's name, for messages.
[[nodiscard]] std::string categoryNames();
/// True for categories whose worlds have moving people.
[[nodiscard]] bool hasPeople(Category c);

/// Throws std::runtime_error if no valid world is found in 200 attempts (never seen).
[[nodiscard]] WorldSpec randomWorld(Category c, uint32_t seed,
                                    const nav::GridPlannerOptions& planner = {});

/// One episode of a benchmark over random worlds: which, where, and how it went.
struct GridEpisode {
    std::size_t category = 0;  ///< index into the categories run
    int index = 0;             ///< the world's index in its category (seed = first seed + index)
    std::string method;
    const WorldSpec* world = nullptr;  ///< valid during the `done` call only
    EpisodeResult result;
    std::string error;  ///< what the episode threw (then result is an Outcome::Error), else ""
};

/// Runs `episode(world, method)` for each category, `per_category` worlds of it (seeds
/// first_seed, first_seed + 1, ...) and each method on the same world, in that order, and
/// hands each to `done`. `stop()` is asked before each episode; true ends the runs there
/// (Ctrl-C). Returns the number of episodes done.
///
/// An exception from a method's first episode, or from the first world of a category, ends
/// the runs with a std::runtime_error naming the episode: an INI or method that cannot run
/// would fail every episode, and minutes of them. From a later episode it is that episode's
/// Outcome::Error (GridEpisode::error, and the result's reason, say what) and the runs go on,
/// so that one world a method cannot take does not lose the others' tallies; a later world
/// that cannot be made is such an error of every method.
std::size_t runEpisodeGrid(
    const std::vector<Category>& categories, int per_category, uint32_t first_seed,
    const std::vector<std::string>& methods, const nav::GridPlannerOptions& planner,
    const std::function<EpisodeResult(const WorldSpec&, const std::string&)>& episode,
    const std::function<void(const GridEpisode&)>& done, const std::function<bool()>& stop);

}  // namespace devslam::sim
