#include "vk_compute.hpp"

#include <cstdlib>
#include <cstring>
#include <fstream>

namespace gpu_test {
namespace {

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed (VkResult " + std::to_string(static_cast<int>(r)) + ")");
}

}  // namespace

Vk::Vk(const std::string& prefer) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "hairlut-gpu-test";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  const VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
  if (r != VK_SUCCESS)
    throw Unavailable("no Vulkan driver (vkCreateInstance returned " + std::to_string(static_cast<int>(r)) +
                      "; Debian: mesa-vulkan-drivers gives lavapipe, Vulkan on the CPU)");
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance_, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  if (n) vkEnumeratePhysicalDevices(instance_, &n, devices.data());
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (!prefer.empty() && std::string(p.deviceName).find(prefer) == std::string::npos) continue;
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, families.data());
    for (std::uint32_t q = 0; q < nq && physical_ == VK_NULL_HANDLE; ++q)
      if (families[q].queueFlags & VK_QUEUE_COMPUTE_BIT) physical_ = d, family_ = q, name_ = p.deviceName, cpu_ = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    if (physical_ != VK_NULL_HANDLE) {
      driver_ = "Vulkan " + std::to_string(VK_API_VERSION_MAJOR(p.apiVersion)) + "." + std::to_string(VK_API_VERSION_MINOR(p.apiVersion)) + "." +
                std::to_string(VK_API_VERSION_PATCH(p.apiVersion)) + ", driver version " + std::to_string(p.driverVersion);
      break;
    }
  }
  if (physical_ == VK_NULL_HANDLE)
    throw Unavailable(n == 0 ? "no Vulkan device (Debian: mesa-vulkan-drivers gives lavapipe, Vulkan on the CPU)"
                             : "no Vulkan device with a compute queue" + (prefer.empty() ? std::string() : " named like \"" + prefer + "\""));
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = family_, qci.queueCount = 1, qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.queueCreateInfoCount = 1, dci.pQueueCreateInfos = &qci;
  check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, family_, 0, &queue_);
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, pci.queueFamilyIndex = family_;
  check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");

  VkDescriptorSetLayoutBinding b[6] = {};
  const VkDescriptorType types[6] = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
                                     VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  for (std::uint32_t i = 0; i < 6; ++i) b[i].binding = i, b[i].descriptorType = types[i], b[i].descriptorCount = 1, b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  VkDescriptorSetLayoutCreateInfo lci{};
  lci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  lci.bindingCount = 6, lci.pBindings = b;
  check(vkCreateDescriptorSetLayout(device_, &lci, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8};
  VkPipelineLayoutCreateInfo plci{};
  plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  plci.setLayoutCount = 1, plci.pSetLayouts = &set_layout_, plci.pushConstantRangeCount = 1, plci.pPushConstantRanges = &push;
  check(vkCreatePipelineLayout(device_, &plci, nullptr, &layout_), "vkCreatePipelineLayout");
  const VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 128}, {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 64}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 192}};
  VkDescriptorPoolCreateInfo dpci{};
  dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpci.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT, dpci.maxSets = 64, dpci.poolSizeCount = 3, dpci.pPoolSizes = sizes;
  check(vkCreateDescriptorPool(device_, &dpci, nullptr, &descriptors_), "vkCreateDescriptorPool");
}

Vk::~Vk() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    for (VkPipeline p : pipelines_) vkDestroyPipeline(device_, p, nullptr);
    for (VkShaderModule m : modules_) vkDestroyShaderModule(device_, m, nullptr);
    for (VkSampler s : samplers_) vkDestroySampler(device_, s, nullptr);
    for (VkImageView v : views_) vkDestroyImageView(device_, v, nullptr);
    for (VkImage i : images_) vkDestroyImage(device_, i, nullptr);
    for (VkBuffer b : buffers_) vkDestroyBuffer(device_, b, nullptr);
    for (VkDeviceMemory m : memory_) vkFreeMemory(device_, m, nullptr);
    vkDestroyDescriptorPool(device_, descriptors_, nullptr);
    vkDestroyPipelineLayout(device_, layout_, nullptr);
    vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
    vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

bool Vk::filters_linearly(VkFormat format) const {
  VkFormatProperties p;
  vkGetPhysicalDeviceFormatProperties(physical_, format, &p);
  return (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
}

std::uint32_t Vk::memory_type(std::uint32_t bits, VkMemoryPropertyFlags want) const {
  VkPhysicalDeviceMemoryProperties p;
  vkGetPhysicalDeviceMemoryProperties(physical_, &p);
  for (std::uint32_t i = 0; i < p.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (p.memoryTypes[i].propertyFlags & want) == want) return i;
  for (std::uint32_t i = 0; i < p.memoryTypeCount; ++i)
    if (bits & (1u << i)) return i;
  throw std::runtime_error("no Vulkan memory type for a resource");
}

VkDeviceMemory Vk::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags want, const char* what) {
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size, mai.memoryTypeIndex = memory_type(req.memoryTypeBits, want);
  VkDeviceMemory mem;
  check(vkAllocateMemory(device_, &mai, nullptr, &mem), what);
  memory_.push_back(mem);  // freed with the device
  return mem;
}

Vk::Buffer Vk::buffer(std::size_t bytes, VkBufferUsageFlags usage) {
  Buffer b;
  b.size = bytes;
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = bytes, bci.usage = usage, bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(device_, &bci, nullptr, &b.buffer), "vkCreateBuffer");
  buffers_.push_back(b.buffer);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  const VkDeviceMemory mem = allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, "vkAllocateMemory (buffer)");
  check(vkBindBufferMemory(device_, b.buffer, mem, 0), "vkBindBufferMemory");
  check(vkMapMemory(device_, mem, 0, VK_WHOLE_SIZE, 0, &b.map), "vkMapMemory");
  return b;
}

VkCommandBuffer Vk::begin() {
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool_, ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  check(vkAllocateCommandBuffers(device_, &ai, &cmd), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  return cmd;
}

void Vk::submit(VkCommandBuffer cmd) {
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1, si.pCommandBuffers = &cmd;
  check(vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
  check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

Vk::Image Vk::texture(VkFormat format, int width, int height, int layers, const void* data, std::size_t bytes) {
  Image img;
  VkImageCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ici.imageType = VK_IMAGE_TYPE_2D, ici.format = format;
  ici.extent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
  ici.mipLevels = 1, ici.arrayLayers = static_cast<std::uint32_t>(layers), ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL, ici.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE, ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(device_, &ici, nullptr, &img.image), "vkCreateImage");
  images_.push_back(img.image);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, img.image, &req);
  const VkDeviceMemory mem = allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "vkAllocateMemory (image)");
  check(vkBindImageMemory(device_, img.image, mem, 0), "vkBindImageMemory");

  const Buffer staging = buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(staging.map, data, bytes);
  VkCommandBuffer cmd = begin();
  VkImageMemoryBarrier bar{};
  bar.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  bar.srcQueueFamilyIndex = bar.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  bar.image = img.image, bar.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, static_cast<std::uint32_t>(layers)};
  bar.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, bar.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, bar.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &bar);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, static_cast<std::uint32_t>(layers)};
  copy.imageExtent = ici.extent;
  vkCmdCopyBufferToImage(cmd, staging.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
  bar.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, bar.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  bar.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT, bar.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0, nullptr, 1, &bar);
  submit(cmd);

  VkImageViewCreateInfo vci{};
  vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vci.image = img.image, vci.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY, vci.format = format;
  vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, static_cast<std::uint32_t>(layers)};
  check(vkCreateImageView(device_, &vci, nullptr, &img.view), "vkCreateImageView");
  views_.push_back(img.view);
  return img;
}

VkSampler Vk::sampler(VkFilter filter) {
  VkSamplerCreateInfo sci{};
  sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  sci.magFilter = sci.minFilter = filter, sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sci.maxLod = 0.0f;
  VkSampler s;
  check(vkCreateSampler(device_, &sci, nullptr, &s), "vkCreateSampler");
  samplers_.push_back(s);
  return s;
}

VkPipeline Vk::pipeline(const std::vector<std::uint32_t>& spirv) {
  VkShaderModuleCreateInfo mci{};
  mci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  mci.codeSize = spirv.size() * 4, mci.pCode = spirv.data();
  VkShaderModule module;
  check(vkCreateShaderModule(device_, &mci, nullptr, &module), "vkCreateShaderModule");
  modules_.push_back(module);
  VkComputePipelineCreateInfo cci{};
  cci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  cci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  cci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT, cci.stage.module = module, cci.stage.pName = "main";
  cci.layout = layout_;
  VkPipeline p;
  check(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &cci, nullptr, &p), "vkCreateComputePipelines");
  pipelines_.push_back(p);
  return p;
}

void Vk::run(VkPipeline pipeline, const Image& np, const Image& mp, VkSampler sampler, const Buffer& uniforms, const Buffer& in, const Buffer& out,
             const Buffer& rows, std::uint32_t count, std::uint32_t mode) {
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = descriptors_, ai.descriptorSetCount = 1, ai.pSetLayouts = &set_layout_;
  VkDescriptorSet set;
  check(vkAllocateDescriptorSets(device_, &ai, &set), "vkAllocateDescriptorSets");
  const VkDescriptorImageInfo images[2] = {{sampler, np.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, {sampler, mp.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}};
  const VkDescriptorBufferInfo buffers[4] = {{uniforms.buffer, 0, VK_WHOLE_SIZE}, {in.buffer, 0, VK_WHOLE_SIZE}, {out.buffer, 0, VK_WHOLE_SIZE},
                                             {rows.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[6] = {};
  for (std::uint32_t i = 0; i < 6; ++i) {
    w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, w[i].dstSet = set, w[i].dstBinding = i, w[i].descriptorCount = 1;
    if (i < 2) w[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, w[i].pImageInfo = &images[i];
    else w[i].descriptorType = i == 2 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, w[i].pBufferInfo = &buffers[i - 2];
  }
  vkUpdateDescriptorSets(device_, 6, w, 0, nullptr);
  VkCommandBuffer cmd = begin();
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set, 0, nullptr);
  const std::uint32_t push[2] = {count, mode};
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, push);
  vkCmdDispatch(cmd, (count + 63) / 64, 1, 1);
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT, mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
  submit(cmd);
  check(vkFreeDescriptorSets(device_, descriptors_, 1, &set), "vkFreeDescriptorSets");
}

std::vector<std::uint32_t> read_spirv(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) throw std::runtime_error(path + ": cannot open the SPIR-V file");
  const std::streamsize n = f.tellg();
  if (n <= 0 || n % 4 != 0) throw std::runtime_error(path + ": not a SPIR-V module (size " + std::to_string(n) + ")");
  std::vector<std::uint32_t> words(static_cast<std::size_t>(n) / 4);
  f.seekg(0);
  f.read(reinterpret_cast<char*>(words.data()), n);
  if (words[0] != 0x07230203u) throw std::runtime_error(path + ": not a SPIR-V module (bad magic number)");
  return words;
}

Args parse_args(int argc, char** argv, std::size_t points) {
  Args a;
  a.points = points;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) throw std::invalid_argument(k + ": needs a value");
    const std::string v = argv[++i];
    if (k == "--tables") a.tables = v;
    else if (k == "--spirv") a.spirv = v;
    else if (k == "--out") a.out = v;
    else if (k == "--device") a.device = v;
    else if (k == "--points") {
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end || n < 8 || n > 10000000) throw std::invalid_argument("--points: an integer from 8 to 10000000 (got " + v + ")");
      a.points = static_cast<std::size_t>(n);
    } else {
      throw std::invalid_argument("unknown option " + k);
    }
  }
  if (a.tables.empty() || a.spirv.empty() || a.out.empty()) throw std::invalid_argument("--tables, --spirv and --out are required");
  return a;
}

}  // namespace gpu_test
