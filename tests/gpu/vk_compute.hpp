// A minimal Vulkan compute harness for the GLSL runtime's test: one device and queue, 2D array
// textures uploaded once, host-visible buffers, and a compute pipeline with the test's fixed
// layout (set 0: binding 0 and 1 combined image samplers, 2 a uniform buffer, 3, 4 and 5 storage
// buffers; 8 bytes of push constants). Everything is destroyed with the object.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace gpu_test {

/// No Vulkan driver or device: the test is skipped, saying why.
struct Unavailable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Vk {
 public:
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    void* map = nullptr;
    std::size_t size = 0;
  };

  /// The first physical device whose name contains `prefer` (empty: the first one listed).
  explicit Vk(const std::string& prefer);
  ~Vk();
  Vk(const Vk&) = delete;
  Vk& operator=(const Vk&) = delete;

  std::string device_name() const { return name_; }
  std::string driver_info() const { return driver_; }
  bool is_cpu() const { return cpu_; }
  /// Whether the format can be sampled with a linear filter (optimal tiling).
  bool filters_linearly(VkFormat format) const;

  /// A sampled 2D array texture of `layers` layers of width × height texels, filled from data.
  Image texture(VkFormat format, int width, int height, int layers, const void* data, std::size_t bytes);
  /// A host-visible, coherent buffer, mapped.
  Buffer buffer(std::size_t bytes, VkBufferUsageFlags usage);
  /// A clamp-to-edge sampler with the given filter (no mipmaps).
  VkSampler sampler(VkFilter filter);
  /// A compute pipeline from SPIR-V words, in the test's layout.
  VkPipeline pipeline(const std::vector<std::uint32_t>& spirv);

  /// Binds the textures (with the sampler) and buffers (in, out, rows at 3, 4, 5), pushes (count, mode) and runs groups of
  /// 64 invocations over `count`; returns when the queue is idle.
  void run(VkPipeline pipeline, const Image& np, const Image& mp, VkSampler sampler, const Buffer& uniforms, const Buffer& in,
           const Buffer& out, const Buffer& rows, std::uint32_t count, std::uint32_t mode);

 private:
  std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags want) const;
  // Memory of a type with `want` for `req`, kept until the device goes; `what` names a failure.
  VkDeviceMemory allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags want, const char* what);
  VkCommandBuffer begin();
  void submit(VkCommandBuffer cmd);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptors_ = VK_NULL_HANDLE;
  std::string name_, driver_;
  bool cpu_ = false;
  std::vector<VkDeviceMemory> memory_;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkBuffer> buffers_;
  std::vector<VkSampler> samplers_;
  std::vector<VkShaderModule> modules_;
  std::vector<VkPipeline> pipelines_;
};

/// The SPIR-V words of a .spv file; throws std::runtime_error naming the file.
std::vector<std::uint32_t> read_spirv(const std::string& path);

/// The GPU tests' options: --tables FILE --spirv DIR --out DIR [--points N] [--device NAME].
struct Args {
  std::string tables, spirv, out, device;
  std::size_t points = 0;
};
/// Parses them (points: `points` unless given, 8 to 10⁷); throws std::invalid_argument naming the option.
Args parse_args(int argc, char** argv, std::size_t points);

}  // namespace gpu_test
