// sba-slam vocabulary train: a bag-of-words vocabulary for loop closing, trained on the ORB
// features of image folders (loop/vocabulary_training.h does the work).

#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "sbaslam/loop/vocabulary_training.h"

namespace sbaslam::cli {
namespace {

struct VocabularyTrainArguments {
  std::vector<std::string> folders;
  std::string out;
  loop::VocabularyTrainingOptions options;
};

void add_train_command(CLI::App& vocabulary) {
  auto args = std::make_shared<VocabularyTrainArguments>();
  CLI::App* cmd = vocabulary.add_subcommand(
      "train", "Train a vocabulary on the ORB features of the images in some folders");
  cmd->add_option("--images", args->folders, "Folder of .png/.jpg images (repeat for more)")
      ->required();
  cmd->add_option("--out", args->out, "Vocabulary file to write")->required();
  cmd->add_option("--branching", args->options.vocabulary.branching, "Children per tree node")
      ->capture_default_str()
      ->check(CLI::Range(2, 1000));
  cmd->add_option("--levels", args->options.vocabulary.levels, "Levels of the tree below its root")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  cmd->add_option("--seed", args->options.vocabulary.seed, "Seed of the k-means++ draws")
      ->capture_default_str();
  cmd->add_option("--max-features", args->options.max_features, "ORB features per image")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--every", args->options.every, "Use every Nth image of each folder")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  cmd->callback([args] {
    const loop::VocabularyTrainingReport report =
        loop::train_vocabulary_from_folders(args->folders, args->options, args->out);
    fmt::print("{}\n", report.summary(args->out));
  });
}

}  // namespace

void add_vocabulary_command(CLI::App& app) {
  CLI::App* vocabulary =
      app.add_subcommand("vocabulary", "Bag-of-words vocabularies for loop closing");
  vocabulary->require_subcommand(1);
  add_train_command(*vocabulary);
}

}  // namespace sbaslam::cli
