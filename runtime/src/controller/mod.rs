//! The controller: modules, winner-take-all, behaviors, CRBP and the episode
//! runner (placeholder until the controller issue lands).
