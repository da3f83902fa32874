#include "compute/VulkanFixture.h"

#include <cstdlib>
#include <memory>

#include "core/Error.h"

namespace plano::test {
namespace {

/// Owns the shared backend so that it is destroyed before the process exits (and the
/// Vulkan loader unloads), not in a static destructor.
class VulkanEnvironment : public ::testing::Environment {
 public:
  void TearDown() override { backend.reset(); }
  std::unique_ptr<compute::VulkanBackend> backend;
  std::string error;
  bool tried = false;
};

VulkanEnvironment* environment() {
  static VulkanEnvironment* instance =
      static_cast<VulkanEnvironment*>(::testing::AddGlobalTestEnvironment(new VulkanEnvironment));
  return instance;
}
// Registered before main runs the tests, so that its TearDown is called.
[[maybe_unused]] const VulkanEnvironment* registered = environment();

}  // namespace

compute::VulkanBackend* sharedVulkanBackend(std::string* error) {
  VulkanEnvironment* env = environment();
  if (!env->tried) {
    env->tried = true;
    ::setenv("PLANO_VULKAN_VALIDATION", "1", 1);
    try {
      env->backend = std::make_unique<compute::VulkanBackend>(compute::VulkanDevicePreference::Any);
    } catch (const Error& e) {
      env->error = e.what();
    }
  }
  if (error) *error = env->error;
  return env->backend.get();
}

void VulkanTest::SetUp() {
  std::string error;
  backend_ = sharedVulkanBackend(&error);
  ASSERT_NE(backend_, nullptr) << "no Vulkan backend (scripts/test.sh runs the tests on lavapipe): " << error;
  ASSERT_TRUE(backend_->context().settings().validation);
  messagesBefore_ = backend_->context().validationMessageCount();
}

void VulkanTest::TearDown() {
  if (!backend_) return;
  const auto messages = backend_->context().validationMessages();
  std::string text;
  for (std::size_t i = messagesBefore_; i < messages.size(); ++i) text += messages[i] + "\n";
  EXPECT_EQ(messages.size(), messagesBefore_) << "validation messages:\n" << text;
}

}  // namespace plano::test
