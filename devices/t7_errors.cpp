#include "devices/t7_errors.hpp"

namespace bellows::t7 {
namespace {

struct KnownError {
  int number;
  const char* name;
  const char* description;  // LabJack's, shortened where it is long
};

// Number, name and description as ljm_constants.json's `errors` list has them.
constexpr KnownError kKnownErrors[] = {
    {1201, "LJME_MBE1_ILLEGAL_FUNCTION", "The device received an invalid function code."},
    {1202, "LJME_MBE2_ILLEGAL_DATA_ADDRESS",
     "The device received an invalid address, or an illegal access such as writing a read only register."},
    {1203, "LJME_MBE3_ILLEGAL_DATA_VALUE",
     "The device received a value that could not be written to the specified address."},
    {1204, "LJME_MBE4_SLAVE_DEVICE_FAILURE", "The device encountered an error."},
    {2371, "AIN_SETTLING_INVALID", "Specified settling is greater than device max."},
    {2375, "AIN_RESOLUTION_INVALID", "Selected resolution is invalid. Valid range is 0-5 for T4 and 0-12 for T7."},
    {2554, "EF_CLOCK_SOURCE_NOT_ENABLED", "Attempted to disable a clock source that is not running."},
    {2558, "EF_32BIT_REQUIRES_BOTH_CLOCK0and1",
     "Both Clock_Source 1 and Clock_Source 2 must be disabled before enabling Clock_Source 0."},
    {2559, "EF_DIVISOR_VALUE_INVALID",
     "The specified divisor value is not supported. Supported values are: 1,2,4,8,16,32,64,256."},
    {2563, "EF_LINE_MUST_BE_LOW_BEFORE_STARTING",
     "The DIO line must be set to output low to ensure proper signal generation."},
    {2565, "EF_VALUE_GREATER_THAN_PERIOD", "The value must be less than the selected ClockSource's roll value."},
    {2605, "STREAM_IS_ACTIVE", "The requested operation can not be performed while stream is running."},
    {2566, "EF_CAN_NOT_CHANGE_INDEX_WHILE_ENABLED",
     "The index of a DIO_EF can not be changed while that DIO_EF is enabled."},
};

const KnownError* find(int number) {
  for (const KnownError& e : kKnownErrors) {
    if (e.number == number) return &e;
  }
  return nullptr;
}

}  // namespace

const char* error_name(int number) {
  const KnownError* e = find(number);
  return e != nullptr ? e->name : "";
}

const char* error_description(int number) {
  const KnownError* e = find(number);
  return e != nullptr ? e->description : "";
}

}  // namespace bellows::t7
