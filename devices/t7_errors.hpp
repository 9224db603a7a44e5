// LabJack's error numbers that bellows can meet on a T7 (the `errors` list of LabJack's
// ljm_constants.json, labjack/ljm_constants; docs/labjack-t7.md): t7-sim refuses with them, and
// bellows names them when a T7 refuses a request (it reads LAST_ERR_DETAIL, 55000, after an
// exception).
#pragma once

namespace bellows::t7 {

inline constexpr int kErrorIllegalDataAddress = 1202;       // LJME_MBE2_ILLEGAL_DATA_ADDRESS (exception 2)
inline constexpr int kErrorIllegalDataValue = 1203;         // LJME_MBE3_ILLEGAL_DATA_VALUE (exception 3)
inline constexpr int kErrorAinSettlingInvalid = 2371;       // AIN_SETTLING_INVALID ("greater than device max")
inline constexpr int kErrorAinResolutionInvalid = 2375;     // AIN_RESOLUTION_INVALID ("0-12 for T7")
inline constexpr int kErrorClockNotEnabled = 2554;          // EF_CLOCK_SOURCE_NOT_ENABLED
inline constexpr int kErrorClock0NeedsClocks12Off = 2558;   // EF_32BIT_REQUIRES_BOTH_CLOCK0and1
inline constexpr int kErrorDivisorInvalid = 2559;           // EF_DIVISOR_VALUE_INVALID
inline constexpr int kErrorLineMustBeLow = 2563;            // EF_LINE_MUST_BE_LOW_BEFORE_STARTING
inline constexpr int kErrorValueGreaterThanPeriod = 2565;   // EF_VALUE_GREATER_THAN_PERIOD
inline constexpr int kErrorIndexChangeWhileEnabled = 2566;  // EF_CAN_NOT_CHANGE_INDEX_WHILE_ENABLED
inline constexpr int kErrorStreamIsActive = 2605;           // STREAM_IS_ACTIVE

/// LabJack's name for an error number ("EF_VALUE_GREATER_THAN_PERIOD"), or "" when bellows does not
/// know it (static storage).
const char* error_name(int number);
/// LabJack's description of it ("" when unknown; static storage).
const char* error_description(int number);

}  // namespace bellows::t7
